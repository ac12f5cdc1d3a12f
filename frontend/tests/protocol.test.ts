import { describe, expect, it } from "vitest";
import type { DemonResult } from "../src/api/types";
import { MISSING } from "../src/lib/format";
import {
  countsTable,
  formatDuration,
  formatShare,
  protocolProgress,
  protocolSummary,
  protocolTitle,
  resultRows,
} from "../src/lib/protocol";

const running = { status: "running" as const, episodes_done: 150, episodes_total: 300, seconds: null };

describe("formatDuration", () => {
  it("reads like a person would say it", () => {
    expect(formatDuration(0.4379)).toBe("0.4 s");
    expect(formatDuration(9.9)).toBe("9.9 s");
    expect(formatDuration(9.96)).toBe("10 s");
    expect(formatDuration(42.4)).toBe("42 s");
    expect(formatDuration(59.6)).toBe("1 min 00 s");
    expect(formatDuration(125)).toBe("2 min 05 s");
    expect(formatDuration(3780)).toBe("1 h 03 min");
  });
  it("shows missing, negative and infinite durations as a dash", () => {
    expect(formatDuration(null)).toBe(MISSING);
    expect(formatDuration(-1)).toBe(MISSING);
    expect(formatDuration(Number.POSITIVE_INFINITY)).toBe(MISSING);
  });
});

describe("protocolProgress", () => {
  it("counts the episodes and estimates what is left from the pace so far", () => {
    const shown = protocolProgress(running, 2);
    expect(shown.fraction).toBe(0.5);
    expect(shown.counted).toBe("150 / 300 episodes · 50 %");
    expect(shown.timing).toBe("2.0 s elapsed · about 2.0 s left");
  });
  it("promises no time left before the first episode, and works without a clock", () => {
    expect(protocolProgress({ ...running, episodes_done: 0 }, 0.3).timing).toBe("0.3 s elapsed");
    expect(protocolProgress(running, null).timing).toBe("");
  });
  it("says what a job does once every episode is done but it still runs", () => {
    const shown = protocolProgress({ ...running, episodes_done: 300 }, 12);
    expect(shown.fraction).toBe(1);
    expect(shown.timing).toBe("12 s elapsed · evaluating: Monte-Carlo truth and test runs");
  });
  it("reports the server's time once finished, and the end of a cancelled job", () => {
    const finished = protocolProgress({ ...running, status: "finished", episodes_done: 300, seconds: 0.43 }, 5);
    expect(finished.counted).toBe("300 / 300 episodes · 100 %");
    expect(finished.timing).toBe("finished in 0.4 s");
    const cancelled = protocolProgress(
      { ...running, status: "cancelled", episodes_done: 1234, episodes_total: 100000 },
      5,
    );
    expect(cancelled.counted).toBe("1,234 / 100,000 episodes · 1 %");
    expect(cancelled.timing).toBe("cancelled");
    const interrupted = protocolProgress({ ...running, status: "interrupted", episodes_done: 150 }, null);
    expect(interrupted.counted).toBe("150 / 300 episodes · 50 %");
    expect(interrupted.timing).toBe("interrupted: the server stopped while it ran");
  });
  it("never shows more than all, nor 100 % before the end", () => {
    expect(protocolProgress({ ...running, episodes_done: 400 }, 1).fraction).toBe(1);
    expect(protocolProgress({ ...running, episodes_done: 2999, episodes_total: 3000 }, 1).counted).toContain("99 %");
    expect(protocolProgress({ ...running, status: "finished", episodes_total: 0, episodes_done: 0 }, 1).fraction).toBe(
      1,
    );
  });
});

const experiment1: DemonResult[] = [
  {
    name: "base",
    prediction: -0.0763,
    truth: -0.1322,
    truth_stderr: 0.0137,
    error: 0.0559,
    thesis: null,
    counts: null,
  },
  {
    name: "steps_to_end",
    prediction: 45.542,
    truth: 50.0538,
    truth_stderr: 0.5084,
    error: -4.5118,
    thesis: 30.7,
    counts: null,
  },
];

const experiment3: DemonResult[] = [
  { name: "colour", prediction: 0, truth: null, truth_stderr: null, error: null, thesis: null, counts: null },
  {
    name: "base",
    prediction: -0.0065,
    truth: null,
    truth_stderr: null,
    error: null,
    thesis: null,
    counts: { positive: 10, negative: 0, none: 0 },
  },
];

describe("resultRows", () => {
  it("gives horde run's columns: prediction, truth ± se, error, error %, thesis", () => {
    expect(resultRows(experiment1)).toEqual([
      {
        name: "base",
        prediction: "-0.076",
        truth: "-0.132 ± 0.014",
        error: "0.056",
        relative: "+42.3 %",
        thesis: MISSING,
      },
      {
        name: "steps_to_end",
        prediction: "45.542",
        truth: "50.054 ± 0.508",
        error: "-4.512",
        relative: "−9.0 %",
        thesis: "30.700",
      },
    ]);
  });
  it("leaves a dash where a protocol computes no truth", () => {
    const [colour] = resultRows(experiment3);
    expect(colour).toEqual({
      name: "colour",
      prediction: "0.000",
      truth: MISSING,
      error: MISSING,
      relative: MISSING,
      thesis: MISSING,
    });
  });
});

describe("countsTable", () => {
  it("puts the test runs beside the thesis's, each with its share", () => {
    expect(countsTable(experiment3, { positive: 100, negative: 0, none: 0 })).toEqual({
      demon: "base",
      rows: [
        { key: "protocol", label: "this protocol", positive: "10 (100 %)", negative: "0 (0 %)", none: "0 (0 %)" },
        { key: "thesis", label: "the thesis", positive: "100 (100 %)", negative: "0 (0 %)", none: "0 (0 %)" },
      ],
    });
  });
  it("has no thesis row without the thesis's counts, and no table without test runs", () => {
    expect(countsTable(experiment3, null)?.rows.map((r) => r.key)).toEqual(["protocol"]);
    expect(countsTable(experiment1, { positive: 35, negative: 28, none: 37 })).toBeNull();
  });
  it("shares round to whole percents, and no runs at all give plain counts", () => {
    expect(formatShare(1, 3)).toBe("1 (33 %)");
    expect(formatShare(0, 0)).toBe("0");
  });
});

describe("titles and summaries", () => {
  it("names what was run, in the singular where it is one", () => {
    expect(protocolTitle({ name: "experiment3", trials: 1, episodes: 300, max_steps: 100 })).toBe(
      "experiment3: 1 trial × 300 episodes (at most 100 steps each)",
    );
    expect(protocolTitle({ name: null, trials: 10, episodes: 10000, max_steps: 1 })).toBe(
      "protocol: 10 trials × 10,000 episodes (at most 1 step each)",
    );
  });
  it("sums up the steps, the speed and the truth's rollouts", () => {
    expect(protocolSummary({ steps: 8981, seconds: 0.438, rollouts: 0 })).toBe(
      "8,981 steps in 0.4 s (20,505 steps/s); no Monte-Carlo truth (the scenario asks for 0 rollouts)",
    );
    expect(protocolSummary({ steps: null, seconds: null, rollouts: 5000 })).toBe(
      "truth: 5,000 Monte-Carlo rollouts per trial",
    );
  });
});
