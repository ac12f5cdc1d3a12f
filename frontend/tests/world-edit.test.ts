import { describe, expect, it } from "vitest";
import { freshName, moveRect, newRegion, rectFrom, resizeRect, snap, startAt } from "../src/lib/world-edit";

const world = { width: 500, height: 500, step: 100 };

describe("snap", () => {
  it("rounds to the step grid", () => {
    expect(snap(149, 100)).toBe(100);
    expect(snap(151, 100)).toBe(200);
    expect(snap(33, 0)).toBe(33);
  });
});

describe("rectFrom", () => {
  it("orders, snaps and keeps the rectangle inside the world, one step at least", () => {
    expect(rectFrom([260, 410], [110, 190], world)).toEqual([100, 200, 300, 400]);
    expect(rectFrom([-80, 480], [620, 530], world)).toEqual([0, 400, 500, 500]);
    expect(rectFrom([120, 120], [130, 130], world)).toEqual([100, 100, 200, 200]);
    expect(rectFrom([490, 490], [499, 499], world)).toEqual([400, 400, 500, 500]);
  });
});

describe("moveRect", () => {
  it("moves by whole steps and stops at the walls", () => {
    expect(moveRect([100, 200, 200, 300], 140, -60, world)).toEqual([200, 100, 300, 200]);
    expect(moveRect([100, 200, 200, 300], 900, 900, world)).toEqual([400, 400, 500, 500]);
    expect(moveRect([0, 0, 200, 100], -50, -300, world)).toEqual([0, 0, 200, 100]);
  });
});

describe("resizeRect", () => {
  it("drags one corner and keeps the opposite one", () => {
    expect(resizeRect([100, 200, 200, 300], "x1y1", [380, 420], world)).toEqual([100, 200, 400, 400]);
    expect(resizeRect([100, 200, 200, 300], "x0y0", [10, 90], world)).toEqual([0, 100, 200, 300]);
    // Dragged past the opposite corner's x: the rectangle turns over; onto its y: one step high at least.
    expect(resizeRect([100, 200, 200, 300], "x1y0", [40, 290], world)).toEqual([0, 300, 100, 400]);
    expect(resizeRect([100, 200, 200, 300], "x1y0", [40, 120], world)).toEqual([0, 100, 100, 300]);
  });
});

describe("startAt", () => {
  it("is the nearest lattice point inside the world", () => {
    expect(startAt([30, 40], world)).toEqual([0, 0]);
    expect(startAt([260, 140], world)).toEqual([300, 100]);
    expect(startAt([499, 499], world)).toEqual([400, 400]);
  });
});

describe("newRegion", () => {
  it("names it after its kind and gives terminals and indicators what they need", () => {
    expect(freshName("zone", [{ name: "zone1" }, { name: "zone3" }])).toBe("zone2");
    expect(newRegion("terminal", [0, 0, 100, 100], [])).toEqual({
      name: "terminal1",
      kind: "terminal",
      rect: [0, 0, 100, 100],
      reward: 1,
    });
    expect(newRegion("indicator", [0, 0, 100, 100], []).colors).toHaveLength(2);
  });
});
