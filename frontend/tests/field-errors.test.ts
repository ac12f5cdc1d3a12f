import { describe, expect, it } from "vitest";
import type { ValidationProblem } from "../src/api/types";
import { locationPath, placeProblems } from "../src/lib/field-errors";
import { cleanMessage } from "../src/lib/messages";

const problem = (loc: (string | number)[], msg: string): ValidationProblem => ({ loc, msg, type: "value_error" });

describe("locationPath", () => {
  it("drops the request part and pydantic's union tags", () => {
    expect(locationPath(["body", "lambda"])).toEqual(["lambda"]);
    expect(locationPath(["query", "hz"])).toEqual(["hz"]);
    expect(locationPath(["body", "RunTemplate", "seed"])).toEqual(["seed"]);
    expect(locationPath(["body", "cumulant", "SensorExpr", "sensor"])).toEqual(["cumulant", "sensor"]);
    expect(locationPath(["body", "cumulant", "float"])).toEqual(["cumulant"]);
    expect(locationPath(["body", "regions", 0, "rect"])).toEqual(["regions", 0, "rect"]);
    expect(locationPath(["body", "x", "function-after[_check(), Region]"])).toEqual(["x"]);
  });
});

describe("placeProblems", () => {
  const demonFields = ["name", "lambda", "cumulant", "outcome", "continuation", "policy", "policy.temperature"];

  it("puts a problem at the field its location names", () => {
    const placed = placeProblems([problem(["body", "lambda"], "Input should be less than or equal to 1")], demonFields);
    expect(placed.byField.get("lambda")).toEqual(["Input should be less than or equal to 1"]);
    expect(placed.general).toEqual([]);
  });

  it("uses the deepest registered field", () => {
    const placed = placeProblems(
      [problem(["body", "policy", "temperature"], "Input should be greater than 0")],
      demonFields,
    );
    expect([...placed.byField.keys()]).toEqual(["policy.temperature"]);
    const deeper = placeProblems([problem(["body", "policy", "epsilon"], "too big")], demonFields);
    expect([...deeper.byField.keys()]).toEqual(["policy"]);
  });

  it("merges the repeated messages of a union's members", () => {
    const placed = placeProblems(
      [
        problem(["body", "cumulant", "float"], "Input should be a valid number"),
        problem(["body", "cumulant", "SensorExpr", "sensor"], "Field required"),
        problem(["body", "cumulant", "PredictionExpr", "prediction"], "Field required"),
      ],
      demonFields,
    );
    expect(placed.byField.get("cumulant")).toEqual(["Input should be a valid number", "Field required"]);
  });

  it("sends a whole-body problem to the one field its message names", () => {
    const msg = "Value error, demon 'x': continuation can take values in [2, 2]; it must stay in [0, 1]";
    const placed = placeProblems([problem(["body"], msg)], demonFields);
    expect(placed.byField.get("continuation")).toEqual([
      "demon 'x': continuation can take values in [2, 2]; it must stay in [0, 1]",
    ]);
  });

  it("keeps a problem for the whole form when no single field is named", () => {
    const placed = placeProblems(
      [problem(["body"], "Value error, demon 'x' refers to unknown demon 'ghost'")],
      demonFields,
    );
    expect(placed.byField.size).toBe(0);
    expect(placed.general).toEqual(["demon 'x' refers to unknown demon 'ghost'"]);
  });

  it("does not take a sensor such as in:goal for a field named goal", () => {
    const placed = placeProblems([problem(["body"], "unknown sensor 'in:goal'")], ["goal", "name"]);
    expect(placed.general).toEqual(["unknown sensor 'in:goal'"]);
  });

  it("places a region's problem at the region's field the message names", () => {
    const fields = ["name", "start", "regions.0", "regions.0.rect", "regions.0.reward", "regions.0.name"];
    const placed = placeProblems(
      [
        problem(["body", "regions", 0], "Value error, terminal region 'a' needs a reward"),
        problem(["body", "regions", 0, "rect"], "Value error, rect must be [x0, y0, x1, y1] with x0 < x1 and y0 < y1"),
        problem(["body"], "Value error, start must lie inside the world"),
      ],
      fields,
    );
    expect(placed.byField.get("regions.0.reward")).toEqual(["terminal region 'a' needs a reward"]);
    expect(placed.byField.get("regions.0.rect")?.[0]).toMatch(/^rect must be/);
    expect(placed.byField.get("start")).toEqual(["start must lie inside the world"]);
  });

  it("finds query and path parameters by their names", () => {
    const placed = placeProblems(
      [problem(["query", "hz"], "Input should be greater than 0"), problem(["path", "name"], "String should match")],
      ["hz", "name"],
    );
    expect(placed.byField.get("hz")).toEqual(["Input should be greater than 0"]);
    expect(placed.byField.get("name")).toEqual(["String should match"]);
  });
});

describe("cleanMessage", () => {
  it("drops pydantic's prefix", () => {
    expect(cleanMessage("Value error, rect must be ordered")).toBe("rect must be ordered");
    expect(cleanMessage("Field required")).toBe("Field required");
  });
});
