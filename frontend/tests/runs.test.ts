import { describe, expect, it } from "vitest";
import { formatDuration } from "../src/lib/protocol";
import { FULL_SPEED, launchEstimate, matchesFilter, runDuration, speedChoice } from "../src/lib/runs";

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

describe("launchEstimate", () => {
  it("gives the time at a speed that finishes within the hour, and full speed's beside it", () => {
    expect(launchEstimate(100, 100, 20, 200_000)).toBe(
      "100 episodes of up to 100 steps: up to 8 min 20 s at 20 steps/s (full speed: about 0.1 s).",
    );
    expect(launchEstimate(40_000, 100, null, 200_000)).toBe(
      "40,000 episodes of up to 100 steps: about 20 s at full speed.",
    );
  });
  it("describes a speed too slow to finish by its pace, never as hundreds of hours", () => {
    const text = launchEstimate(40_000, 40, 5, 40_000);
    expect(text).toBe(
      "40,000 episodes of up to 40 steps. At 5 steps/s: at least 7 episodes a minute, to watch; the whole protocol needs more than an hour at this speed (full speed: about 40 s).",
    );
    expect(text).not.toMatch(/\d+ h/);
    expect(launchEstimate(1000, 500, 0.5, 1500)).toContain("an episode in up to 16 min 40 s");
  });
  it("says a run without an episode count runs until paused", () => {
    expect(launchEstimate(0, 100, 20, 200_000)).toBe("Runs until paused (no episode count).");
    expect(launchEstimate(undefined, 100, null, 200_000)).toBe("Runs until paused (no episode count).");
  });
});
