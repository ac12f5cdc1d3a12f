import { describe, expect, it } from "vitest";
import type { Region } from "../src/api/types";
import { KIND_COLORS, gridLines, regionFills, regionNames, sensorNames, startPoint } from "../src/lib/world";

const regions: Region[] = [
  { name: "goal", kind: "terminal", rect: [400, 400, 500, 500], reward: 1 },
  { name: "pit", kind: "terminal", rect: [400, 200, 500, 300], reward: -1 },
  { name: "wall", kind: "obstacle", rect: [100, 200, 200, 300] },
  {
    name: "lamp",
    kind: "indicator",
    rect: [300, 200, 400, 300],
    colors: [
      { name: "yellow", value: 1, probability: 0.5 },
      { name: "purple", value: -1, probability: 0.5 },
    ],
  },
  { name: "critical", kind: "zone", rect: [0, 0, 200, 200] },
];

describe("sensorNames", () => {
  it("lists the sensors in the server's order", () => {
    expect(sensorNames({ regions })).toEqual([
      "x",
      "y",
      "bump",
      "steps",
      "reward",
      "in:goal",
      "in:pit",
      "in:wall",
      "in:lamp",
      "in:critical",
      "color:lamp",
      "terminal",
    ]);
    expect(sensorNames({})).toEqual(["x", "y", "bump", "steps", "reward", "terminal"]);
  });
});

describe("startPoint and gridLines", () => {
  it("takes a start point as it is and the centre of a start rectangle", () => {
    expect(startPoint({ start: [0, 0] })).toEqual([0, 0]);
    expect(startPoint({ start: [0, 0, 200, 100] })).toEqual([100, 50]);
  });
  it("draws a line at every step, none when too dense", () => {
    expect(gridLines(500, 100)).toEqual([100, 200, 300, 400]);
    expect(gridLines(450, 100)).toEqual([100, 200, 300, 400]);
    expect(gridLines(500, 1)).toEqual([]);
    expect(gridLines(500, 0)).toEqual([]);
  });
});

describe("regionFills", () => {
  const isColor = (name: string) => ["yellow", "purple"].includes(name);
  const fill = (name: string) => regionFills(regions.find((r) => r.name === name) as Region, isColor);
  it("colours each kind", () => {
    expect(fill("goal")).toEqual([{ color: KIND_COLORS.positive, opacity: 0.85 }]);
    expect(fill("pit")).toEqual([{ color: KIND_COLORS.negative, opacity: 0.85 }]);
    expect(fill("wall")).toEqual([{ color: KIND_COLORS.obstacle, opacity: 1 }]);
    expect(fill("critical")[0]?.opacity).toBeLessThan(1);
    expect(fill("lamp").map((f) => f.color)).toEqual(["yellow", "purple"]);
  });
  it("draws a terminal whose reward depends on an indicator in a neutral colour", () => {
    const swap: Region = {
      name: "left",
      kind: "terminal",
      rect: [0, 400, 100, 500],
      reward: { indicator: "lamp", values: { yellow: 1, purple: -1 } },
    };
    expect(regionFills(swap, isColor)).toEqual([{ color: KIND_COLORS.neutral, opacity: 0.85 }]);
  });
  it("lists region names by kind", () => {
    expect(regionNames({ regions }, ["terminal"])).toEqual(["goal", "pit"]);
  });
});
