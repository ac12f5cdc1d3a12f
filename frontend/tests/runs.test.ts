import { describe, expect, it } from "vitest";
import { formatDuration } from "../src/lib/protocol";
import { FULL_SPEED, matchesFilter, runDuration, speedChoice } from "../src/lib/runs";

describe("runDuration", () => {
  it("is the thesis's 6.5 hours at 20 steps a second, seconds at full speed", () => {
    // 10,000 episodes of at most 100 steps: an upper bound of 1,000,000 steps.
    expect(runDuration(10_000, 100, 20, 200_000)).toBe(50_000);
    expect(formatDuration(runDuration(10_000, 100, 20, 200_000))).toBe("13 h 53 min");
    expect(runDuration(10_000, 100, null, 200_000)).toBe(5);
  });
});

describe("speedChoice", () => {
  it("offers the usual speeds and full speed, and keeps an unusual speed the run has", () => {
    const usual = speedChoice(20);
    expect(usual.value).toBe("20");
    expect(usual.items.at(-1)).toEqual([FULL_SPEED, "full speed"]);
    expect(speedChoice(null).value).toBe(FULL_SPEED);
    const odd = speedChoice(30);
    expect(odd.items.map(([value]) => value)).toContain("30");
    expect(odd.key).not.toBe(usual.key);
  });
});

describe("matchesFilter", () => {
  const run = { id: "abc123", name: "experiment2-large", status: "finished" as const, demons: ["base", "pass"] };
  it("matches every word against name, id, status and demons", () => {
    expect(matchesFilter(run, "")).toBe(true);
    expect(matchesFilter(run, "LARGE finished")).toBe(true);
    expect(matchesFilter(run, "abc pass")).toBe(true);
    expect(matchesFilter(run, "running")).toBe(false);
  });
});
