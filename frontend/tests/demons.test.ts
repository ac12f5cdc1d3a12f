import { describe, expect, it } from "vitest";
import type { Demon } from "../src/api/types";
import { demonSummary, filterDemons, overviewLevels } from "../src/lib/demons";

const metrics = (rupee: number | null, diverged = false) => ({ rupee, ude: 0, delta: 0, cumulant: 0, diverged });

function demon(name: string, control = false, rupee: number | null = 1, diverged = false): Demon {
  return {
    name,
    spec: { name, cumulant: { sensor: "in:goal" } },
    control,
    prediction: 0,
    metrics: metrics(rupee, diverged),
    colour: "#000000",
  } as Demon;
}

describe("filterDemons", () => {
  const demons = [demon("base", true), demon("goal_1"), demon("goal_2", false, null, true), demon("wall")];

  it("keeps the demons whose name or question holds every word", () => {
    const pick = (text: string) => filterDemons(demons, { text, show: "all" }, {}, []).map((d) => d.name);
    expect(pick("")).toEqual(["base", "goal_1", "goal_2", "wall"]);
    expect(pick("GOAL")).toEqual(["base", "goal_1", "goal_2", "wall"]); // every question reads in:goal
    expect(pick("goal_ 2")).toEqual(["goal_2"]);
    expect(pick("nothing")).toEqual([]);
  });

  it("shows learning, diverged, charted or control demons, the stream's metrics first", () => {
    const show = (s: "learning" | "diverged" | "charted" | "control", live = {}) =>
      filterDemons(demons, { text: "", show: s }, live, ["wall"]).map((d) => d.name);
    expect(show("diverged")).toEqual(["goal_2"]);
    expect(show("learning")).toEqual(["base", "goal_1", "wall"]);
    expect(show("diverged", { wall: metrics(1, true) })).toEqual(["goal_2", "wall"]);
    expect(show("charted")).toEqual(["wall"]);
    expect(show("control")).toEqual(["base"]);
  });
});

describe("demonSummary", () => {
  it("counts learning and diverged demons and averages RUPEE over those that learn", () => {
    const demons = [demon("a", false, 1), demon("b", false, 3), demon("c", false, 100, true), demon("d", false, null)];
    expect(demonSummary(demons, {})).toEqual({ demons: 4, learning: 3, diverged: 1, meanRupee: 2 });
    expect(demonSummary([], {}).meanRupee).toBeNull();
  });
});

describe("overviewLevels", () => {
  it("puts probabilities and step counts on one signed log scale", () => {
    const levels = overviewLevels([0, 99, -9, null, 1]);
    expect(levels[0]).toBe(0);
    expect(levels[1]).toBeCloseTo(1); // log10(100) is the largest magnitude
    expect(levels[2]).toBeCloseTo(-0.5); // log10(10) / log10(100)
    expect(levels[3]).toBeNaN();
    expect(levels[4]).toBeCloseTo(Math.log10(2) / 2);
  });
});
