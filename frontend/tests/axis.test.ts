import { describe, expect, it } from "vitest";
import { tickDecimals, tickLabels } from "../src/lib/axis";

describe("tickDecimals", () => {
  it("gives the decimals the step between ticks needs", () => {
    expect(tickDecimals(500)).toBe(0);
    expect(tickDecimals(1)).toBe(0);
    expect(tickDecimals(0.5)).toBe(1);
    expect(tickDecimals(0.25)).toBe(2);
    expect(tickDecimals(0.0002)).toBe(4);
    expect(tickDecimals(0.1 + 0.2)).toBe(1); // 0.30000000000000004
  });
  it("is 0 for no step", () => {
    expect(tickDecimals(0)).toBe(0);
    expect(tickDecimals(Number.NaN)).toBe(0);
  });
});

describe("tickLabels", () => {
  it("compacts large steps so that neighbours cannot run together", () => {
    expect(tickLabels([0, 500_000, 1_000_000])).toEqual(["0", "500k", "1M"]);
    expect(tickLabels([0, 250_000, 500_000, 750_000, 1_000_000, 1_250_000])).toEqual([
      "0",
      "250k",
      "500k",
      "750k",
      "1M",
      "1.25M",
    ]);
    expect(tickLabels([0, 5000, 10_000, 15_000])).toEqual(["0", "5k", "10k", "15k"]);
    expect(tickLabels([-2e9, 0, 2e9])).toEqual(["-2G", "0", "2G"]);
  });
  it("leaves numbers below 10,000 as they are", () => {
    expect(tickLabels([0, 2000, 4000, 6000])).toEqual(["0", "2000", "4000", "6000"]);
  });
  it("never repeats a label for small steps", () => {
    const labels = tickLabels([0, 0.0002, 0.0004, 0.0006]);
    expect(labels).toEqual(["0.0000", "0.0002", "0.0004", "0.0006"]);
    expect(new Set(labels).size).toBe(labels.length);
    expect(tickLabels([-0.5, 0, 0.5])).toEqual(["-0.5", "0.0", "0.5"]);
  });
  it("writes no minus zero and keeps gaps for ticks left out", () => {
    expect(tickLabels([-1e-17, 1, null, 3])).toEqual(["0", "1", "", "3"]);
    expect(tickLabels([])).toEqual([]);
  });
});
