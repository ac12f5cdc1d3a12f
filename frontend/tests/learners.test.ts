import { describe, expect, it } from "vitest";
import { type LearnerInfo, STEP_SIZE_TEXT, choices, learnerChoices } from "../src/lib/learners";

const TDRC: LearnerInfo = {
  name: "tdrc",
  text: "TDRC(λ): TDC with regularized corrections",
  paper: "Ghiassian et al. 2020",
  action_values: false,
  secondary: true,
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
});
