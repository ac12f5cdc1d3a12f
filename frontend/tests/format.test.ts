import { describe, expect, it } from "vitest";
import {
  MISSING,
  formatCount,
  formatCountOf,
  nameParts,
  formatEstimate,
  formatHz,
  formatNumber,
  formatRelativeError,
  runLabel,
} from "../src/lib/format";

describe("formatNumber", () => {
  it("shows a fixed number of decimals", () => {
    expect(formatNumber(30.7)).toBe("30.700");
    expect(formatNumber(0.906, 2)).toBe("0.91");
    expect(formatNumber(-1)).toBe("-1.000");
  });
  it("shows missing, NaN and infinite values as a dash", () => {
    expect(formatNumber(null)).toBe(MISSING);
    expect(formatNumber(undefined)).toBe(MISSING);
    expect(formatNumber(Number.NaN)).toBe(MISSING);
    expect(formatNumber(Number.POSITIVE_INFINITY)).toBe(MISSING);
  });
  it("writes tiny and huge magnitudes in exponent form, and zero plainly", () => {
    expect(formatNumber(1.5e-7)).toBe("1.50e-7");
    expect(formatNumber(2.5e8)).toBe("2.50e+8");
    expect(formatNumber(0)).toBe("0.000");
  });
  it("never rounds a small value to a (negative) zero", () => {
    expect(formatNumber(-0.0004, 2)).toBe("-4.00e-4");
    expect(formatNumber(-0.001, 2)).toBe("-1.00e-3");
    expect(formatNumber(-0, 2)).toBe("0.00");
  });
});

describe("counts, estimates, errors and speeds", () => {
  it("separates thousands", () => {
    expect(formatCount(12345)).toBe("12,345");
    expect(formatCount(null)).toBe(MISSING);
  });
  it("says one thing in the singular and any other count in the plural", () => {
    expect(formatCountOf(1, "configuration")).toBe("1 configuration");
    expect(formatCountOf(0, "run")).toBe("0 runs");
    expect(formatCountOf(12345, "step")).toBe("12,345 steps");
    expect(formatCountOf(2, "Monte-Carlo rollout")).toBe("2 Monte-Carlo rollouts");
    expect(formatCountOf(3, "study", "studies")).toBe("3 studies");
  });
  it("writes a mean with its standard error", () => {
    expect(formatEstimate(39.0123, 0.21)).toBe("39.012 ± 0.210");
    expect(formatEstimate(39, null)).toBe("39.000");
    expect(formatEstimate(null, 0.2)).toBe(MISSING);
  });
  it("gives the relative error with its sign", () => {
    expect(formatRelativeError(30.7, 39)).toBe("−21.3 %");
    expect(formatRelativeError(0.21, 0.2)).toBe("+5.0 %");
    expect(formatRelativeError(1, 0)).toBe(MISSING);
    expect(formatRelativeError(null, 1)).toBe(MISSING);
  });
  it("names the speed", () => {
    expect(formatHz(null)).toBe("full speed");
    expect(formatHz(20)).toBe("20 steps/s");
    expect(formatHz(2.5)).toBe("2.5 steps/s");
  });
  it("labels runs by name and short id, an unnamed one by its demons", () => {
    expect(runLabel({ id: "abcdef123", demons: ["base", "steps", "bump", "wall"] })).toBe("abcdef · base, steps +2");
    expect(runLabel({ id: "abcdef123456", name: "experiment1" })).toBe("experiment1 · abcdef");
    expect(runLabel({ id: "abcdef123456", name: null })).toBe("abcdef · no demons");
  });
});

describe("formatTruth and truthOf", () => {
  it("prefer the exact answer to the Monte-Carlo mean", async () => {
    const { formatTruth, truthOf } = await import("../src/lib/format");
    expect(formatTruth({ truth: 14.8, stderr: 0.641, exact: 16.021 })).toBe("16.021 exact");
    expect(formatTruth({ truth: 14.8, stderr: 0.641, exact: null })).toBe("14.800 ± 0.641");
    expect(formatTruth(undefined)).toBe("–");
    expect(truthOf({ truth: 14.8, exact: 16 })).toBe(16);
    expect(truthOf({ truth: 14.8, exact: null })).toBe(14.8);
    expect(truthOf(undefined)).toBeNull();
  });
});

describe("nameParts", () => {
  it("breaks a demon name after its separators, never inside a word", () => {
    expect(nameParts("steps_northeast")).toEqual(["steps_", "northeast"]);
    expect(nameParts("in:goal-2.b")).toEqual(["in:", "goal-", "2.", "b"]);
    expect(nameParts("plain")).toEqual(["plain"]);
    expect(nameParts("a__b").join("")).toBe("a__b");
  });
});
