import { describe, expect, it } from "vitest";
import { ApiError } from "../src/api/client";
import { setupProblems } from "../src/lib/lab";

describe("setupProblems", () => {
  it("puts a 422's problems at the set-up field they name, the rest under the experiment", () => {
    const error = new ApiError(422, "refused", [
      { loc: ["body", "setup", "order"], msg: "order = 40: too large", type: "value_error" },
      { loc: ["body", "setup", "order"], msg: "and odd", type: "value_error" },
      { loc: ["body"], msg: "something else", type: "value_error" },
    ]);
    expect(setupProblems(error)).toEqual({ order: "order = 40: too large; and odd", "": "something else" });
  });
  it("puts any other error under the experiment", () => {
    expect(setupProblems(new Error("network down"))).toEqual({ "": "network down" });
  });
});
