import { describe, expect, it } from "vitest";
import { type LearnerInfo, STEP_SIZE_TEXT, choices, learnerChoices, noTracesWhy } from "../src/lib/learners";

const TDRC: LearnerInfo = {
  name: "tdrc",
  text: "TDRC(λ): TDC with regularized corrections",
  paper: "Ghiassian et al. 2020",
  action_values: false,
  secondary: true,
  traces: true,
  step_sizes: ["constant"],
  parameters: [{ name: "beta", default: 1, low: 0, high: 1000, text: "the regularisation of h" }],
};

describe("learner and step-size choices", () => {
  it("offers the registry's learners (GET /api/learners) by name, each with its line", () => {
    expect(learnerChoices([TDRC])).toEqual([["tdrc", "tdrc: TDRC(λ): TDC with regularized corrections"]]);
  });

  it("explains every step-size mode of the API in one short line, in the table's order", () => {
    expect(Object.keys(STEP_SIZE_TEXT)).toEqual(["constant", "autostep", "tidbd"]);
    for (const text of Object.values(STEP_SIZE_TEXT)) {
      expect(text).not.toContain("\n");
      expect(text.length).toBeLessThan(80);
    }
    expect(choices(STEP_SIZE_TEXT)[1]).toEqual(["autostep", STEP_SIZE_TEXT.autostep]);
  });

  it("says why a learner without traces takes no λ, and nothing for one with traces or not known yet", () => {
    const gtd1: LearnerInfo = { ...TDRC, name: "gtd1", traces: false };
    expect(noTracesWhy([TDRC, gtd1], "gtd1")).toContain("λ 0 only");
    expect(noTracesWhy([TDRC, gtd1], "tdrc")).toBeNull();
    expect(noTracesWhy([], "gtd1")).toBeNull();
  });
});
