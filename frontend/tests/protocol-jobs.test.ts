import { describe, expect, it } from "vitest";
import type { Protocol } from "../src/api/types";
import { jobRows, scenarioGroups, sortRows } from "../src/lib/protocol-jobs";

describe("scenarioGroups", () => {
  it("groups the scenarios that share a name before the first dash", () => {
    const names = ["experiment1", "experiment2-whole", "experiment2-start", "experiment3", "experiment3-base"];
    expect(scenarioGroups(names).map((g) => [g.key, g.scenarios])).toEqual([
      ["experiment2", ["experiment2-whole", "experiment2-start"]],
      ["experiment3", ["experiment3", "experiment3-base"]],
    ]);
  });
});

function job(id: string, name: string, results: [string, number, number | null][]): Protocol {
  return {
    id,
    name,
    seed: 0,
    status: "finished",
    episodes_done: 1,
    episodes_total: 1,
    trials: 1,
    episodes: 100,
    max_steps: 100,
    rollouts: 10,
    seconds: 1,
    steps: 10,
    results: results.map(([demon, prediction, thesis]) => ({
      name: demon,
      prediction,
      truth: prediction + 0.1,
      truth_stderr: 0.01,
      error: -0.1,
      thesis,
    })),
    thesis_counts: null,
    error: "",
    created_at: "2026-01-01T00:00:00Z",
    finished_at: `2026-01-01T00:00:0${id}Z`,
  } as Protocol;
}

describe("jobRows and sortRows", () => {
  const jobs = [
    job("1", "experiment2-whole", [
      ["base", -0.5, null],
      ["critical", 0.95, 0.906],
    ]),
    job("2", "experiment2-small", [
      ["base", -0.4, null],
      ["critical", 0.2, 0.201],
    ]),
  ];

  it("keeps every job's demons, newest first, only those the thesis reports when asked", () => {
    expect(jobRows(jobs, false).map((r) => r.key)).toEqual(["2/base", "2/critical", "1/base", "1/critical"]);
    const thesis = jobRows(jobs, true);
    expect(thesis.map((r) => [r.scenario, r.thesis])).toEqual([
      ["experiment2-small", 0.201],
      ["experiment2-whole", 0.906],
    ]);
    expect(thesis[1]?.offThesis).toBeCloseTo(0.044);
  });

  it("sorts by a column either way, missing numbers last", () => {
    const rows = jobRows(jobs, false);
    expect(sortRows(rows, "prediction", true).map((r) => r.prediction)).toEqual([-0.5, -0.4, 0.2, 0.95]);
    expect(sortRows(rows, "prediction", false).map((r) => r.prediction)).toEqual([0.95, 0.2, -0.4, -0.5]);
    expect(sortRows(rows, "thesis", false).map((r) => r.thesis)).toEqual([0.906, 0.201, null, null]);
    expect(sortRows(rows, "scenario", true).map((r) => r.scenario)[0]).toBe("experiment2-small");
  });
});
