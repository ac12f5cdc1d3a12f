import { describe, expect, it } from "vitest";
import {
  type StudyConfig,
  configLabel,
  defaultAxes,
  parseValues,
  sensitivityCurves,
  sortConfigs,
  splitDiverged,
  studyProgress,
  studySize,
} from "../src/lib/study";
import { ticks } from "../src/views/study-chart";

const band = { mean: [1, 0.5], low: [1, 0.4], high: [1, 0.6] };

function config(index: number, alpha: number, learner: string, error: number, auc = error): StudyConfig {
  return {
    index,
    axes: { "learning.alpha": alpha, "demons.*.learner": learner },
    runs: 3,
    best: false,
    diverged: false,
    truth: "exact",
    episodes: [0, 10],
    error,
    ci_low: error - 0.1,
    ci_high: error + 0.1,
    auc,
    auc_low: auc - 0.1,
    auc_high: auc + 0.1,
    curve: band,
    returns: band,
    demons: {},
  };
}

const configs = [
  config(0, 0.01, "td", 0.5),
  config(1, 0.01, "gq", 0.7),
  config(2, 0.1, "td", 0.2, 0.9),
  config(3, 0.1, "gq", 0.3),
];

describe("parseValues", () => {
  it("reads numbers, words and booleans as typed", () => {
    expect(parseValues("0.01, 1e-3 ,3")).toEqual([0.01, 0.001, 3]);
    expect(parseValues("td, gq, 'gtd'")).toEqual(["td", "gq", "gtd"]);
    expect(parseValues("true,false,,")).toEqual([true, false]);
    expect(parseValues("0x10, 1.2.3")).toEqual(["0x10", "1.2.3"]);
  });
});

describe("configurations", () => {
  it("are named by the last part of each path", () => {
    expect(configLabel({ "learning.alpha": 0.1, "demons.*.learner": "td" })).toBe("alpha=0.1 learner=td");
    expect(configLabel({})).toBe("the base");
  });

  it("sort by error, by AUC or by an axis, either way", () => {
    expect(sortConfigs(configs, "error").map((c) => c.index)).toEqual([2, 3, 0, 1]);
    expect(sortConfigs(configs, "error", false).map((c) => c.index)).toEqual([1, 0, 3, 2]);
    expect(sortConfigs(configs, "auc").map((c) => c.index)).toEqual([3, 0, 1, 2]);
    expect(sortConfigs(configs, "axis:demons.*.learner").map((c) => c.axes["demons.*.learner"])).toEqual([
      "gq",
      "gq",
      "td",
      "td",
    ]);
    const missing = { ...config(4, 1, "td", 0), error: null };
    expect(sortConfigs([missing, ...configs], "error").at(-1)?.index).toBe(4);
  });

  it("default to the numeric axis along and the other one per curve", () => {
    expect(defaultAxes(configs)).toEqual({ x: "learning.alpha", group: "demons.*.learner" });
  });
});

describe("splitDiverged", () => {
  it("leaves the diverged configurations out of what the plots draw", () => {
    const diverged = { ...config(4, 1, "td", 961325199.63), diverged: true };
    const { kept, diverged: out } = splitDiverged([...configs, diverged]);
    expect(kept.map((c) => c.index)).toEqual([0, 1, 2, 3]);
    expect(out.map((c) => c.index)).toEqual([4]);
  });
  it("keeps every configuration when the server does not say", () => {
    expect(splitDiverged(configs).kept).toHaveLength(configs.length);
  });
});

describe("sensitivityCurves", () => {
  it("draws one curve per group, x in order", () => {
    const curves = sensitivityCurves(configs, "learning.alpha", "demons.*.learner", "final");
    const td = curves.find((c) => c.group === "td");
    expect(td?.points.map((p) => [p.x, p.mean])).toEqual([
      [0.01, 0.5],
      [0.1, 0.2],
    ]);
    expect(td?.points[1]?.low).toBeCloseTo(0.1);
  });

  it("takes the best configuration over the axes left out", () => {
    const [all] = sensitivityCurves(configs, "learning.alpha", null, "final");
    expect(all?.points.map((p) => p.config.index)).toEqual([0, 2]);
    const [byAuc] = sensitivityCurves(configs, "learning.alpha", null, "auc");
    expect(byAuc?.points.map((p) => p.config.index)).toEqual([0, 3]);
  });
});

describe("studyProgress", () => {
  it("counts tasks and says the time left while running", () => {
    const study = { status: "running", tasks: 40, tasks_done: 10, seconds_left: 30 } as Parameters<
      typeof studyProgress
    >[0];
    expect(studyProgress(study)).toEqual({ fraction: 0.25, counted: "10 of 40 tasks", left: "about 30 s left" });
    expect(studyProgress({ ...study, seconds_left: 600 }).left).toBe("about 10 min left");
    expect(studyProgress({ ...study, status: "finished" }).left).toBe("");
  });
});

describe("ticks", () => {
  it("puts 1-2-5 steps on a short log axis and decades on a long one", () => {
    expect(ticks(0.2, 1, true)).toEqual([0.2, 0.5, 1]);
    expect(ticks(0.21, 0.95, true)).toEqual([0.4, 0.6, 0.8]); // too few 1-2-5 steps: linear ones
    expect(ticks(0.001, 10, true)).toEqual([0.001, 0.01, 0.1, 1, 10]);
    expect(ticks(0, 100, false)).toEqual([0, 20, 40, 60, 80, 100]);
  });
});

describe("studySize", () => {
  it("counts configurations and runs, singular for one", () => {
    expect(studySize({ configurations: 4, runs: 1 })).toBe("4 configurations x 1 run");
    expect(studySize({ configurations: 1, runs: 2 })).toBe("1 configuration x 2 runs");
  });
});
