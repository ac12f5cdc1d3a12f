import { describe, expect, it } from "vitest";
import type { History } from "../src/api/types";
import { alignHistories, decadeTicks, markColumns, powerLabel, spansDecades, strideIndices } from "../src/lib/series";

function history(demon: string, steps: number[], prediction: (number | null)[]): History {
  const zeros = steps.map(() => 0);
  return {
    demon,
    every: 1,
    capacity: 100,
    step: steps,
    prediction,
    cumulant: zeros,
    delta: zeros,
    rupee: zeros,
    ude: zeros,
  };
}

describe("strideIndices", () => {
  it("keeps everything that fits", () => {
    expect(strideIndices(3, 10)).toEqual([0, 1, 2]);
    expect(strideIndices(0, 10)).toEqual([]);
  });
  it("thins evenly and keeps the first and the newest row", () => {
    const kept = strideIndices(1001, 11);
    expect(kept).toHaveLength(11);
    expect(kept[0]).toBe(0);
    expect(kept.at(-1)).toBe(1000);
    expect(kept[5]).toBe(500);
  });
});

describe("alignHistories", () => {
  it("puts one column per demon against the steps", () => {
    const data = alignHistories(
      [history("a", [1, 2, 3], [0.1, 0.2, 0.3]), history("b", [1, 2, 3], [null, 1, 2])],
      "prediction",
    );
    expect(data).toEqual([
      [1, 2, 3],
      [0.1, 0.2, 0.3],
      [null, 1, 2],
    ]);
  });
  it("cuts a longer history from the oldest end", () => {
    const data = alignHistories([history("a", [1, 2], [1, 2]), history("b", [1, 2, 3], [1, 2, 3])], "prediction");
    expect(data).toEqual([
      [1, 2],
      [1, 2],
      [2, 3],
    ]);
  });
  it("thins long histories", () => {
    const steps = Array.from({ length: 5000 }, (_, i) => i);
    const data = alignHistories([history("a", steps, steps)], "prediction", 100);
    expect(data[0]).toHaveLength(100);
    expect(data[0].at(-1)).toBe(4999);
  });
  it("is empty without histories", () => {
    expect(alignHistories([], "rupee")).toEqual([[]]);
  });
});

describe("spansDecades", () => {
  it("asks for a log axis where the values blow up, as off-policy TD's on Baird's star", () => {
    expect(spansDecades([3, 12, 300, 4e4, 5e11])).toBe(true);
    expect(spansDecades([-3, 12, null, -2e6])).toBe(true);
  });
  it("keeps a linear axis for values within three powers of ten, or far from zero throughout", () => {
    expect(spansDecades([3, 6.2, 6.6, null])).toBe(false);
    expect(spansDecades([0.001, 0.5, 0.9])).toBe(false);
    expect(spansDecades([2000, 2100, 1900])).toBe(false);
    expect(spansDecades([null, Number.NaN])).toBe(false);
  });
});

describe("decadeTicks and powerLabel", () => {
  it("label a log axis from 0 to 10^12 with two powers of ten", () => {
    const ticks = decadeTicks(0, 1e12);
    expect(ticks).toEqual([0, 1e6, 1e12]);
    expect(ticks.map(powerLabel)).toEqual(["0", "1e6", "1e12"]);
  });
  it("mirror negative ranges, every power where there are few, no label for a tick left out", () => {
    expect(decadeTicks(-15, 20)).toEqual([-100, -10, -1, 0, 1, 10, 100].filter((t) => t >= -15 && t <= 20));
    expect(decadeTicks(-2e4, 0)).toEqual([-1e3, 0]);
    expect(powerLabel(-1e5)).toBe("-1e5");
    expect(powerLabel(null)).toBe("");
  });
});

describe("markColumns", () => {
  const steps = [100, 200, 300, 400];
  it("puts each evaluation at the row of the nearest step, the truth with its interval", () => {
    const [prediction, truth, low, high] = markColumns(steps, [
      { step: 190, prediction: 0.5, truth: [0.7, 0.6, 0.8] },
      { step: 1000, prediction: 0.65, truth: [0.7, 0.7, 0.7] },
    ]);
    expect(prediction).toEqual([null, 0.5, null, 0.65]);
    expect(truth).toEqual([null, 0.7, null, 0.7]);
    expect(low).toEqual([null, 0.6, null, 0.7]);
    expect(high).toEqual([null, 0.8, null, 0.7]);
  });
  it("leaves out a mark older than the history", () => {
    const columns = markColumns(steps, [{ step: 50, prediction: 1, truth: [2, 2, 2] }]);
    expect(columns.flat().every((v) => v === null)).toBe(true);
    expect(markColumns([], [{ step: 50, prediction: 1, truth: [2, 2, 2] }])).toEqual([[], [], [], []]);
  });
});
