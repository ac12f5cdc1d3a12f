import { describe, expect, it } from "vitest";
import { LEARNER_TEXT, STEP_SIZE_TEXT, choices } from "../src/lib/learners";

describe("learner and step-size choices", () => {
  it("offers every learner and step-size mode of the API, each explained in one short line", () => {
    expect(Object.keys(LEARNER_TEXT).sort()).toEqual(
      ["etd", "gq", "gtd", "td", "true_online_gtd", "true_online_td"].sort(),
    );
    expect(Object.keys(STEP_SIZE_TEXT)).toEqual(["constant", "autostep", "tidbd"]);
    for (const text of [...Object.values(LEARNER_TEXT), ...Object.values(STEP_SIZE_TEXT)]) {
      expect(text).not.toContain("\n");
      expect(text.length).toBeLessThan(80);
    }
  });

  it("keeps the order of the table as select options", () => {
    expect(choices(STEP_SIZE_TEXT)[1]).toEqual(["autostep", STEP_SIZE_TEXT.autostep]);
  });
});
