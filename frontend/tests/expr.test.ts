import { describe, expect, it } from "vitest";
import { ExprSyntaxError, buildExpr, describeExpr, exprText, type ExprChoice } from "../src/lib/expr";

describe("buildExpr", () => {
  it("builds the common cases", () => {
    expect(buildExpr({ kind: "constant", value: -0.01 })).toBe(-0.01);
    expect(buildExpr({ kind: "sensor", sensor: "bump" })).toEqual({ sensor: "bump" });
    expect(buildExpr({ kind: "inside", region: "goal" })).toEqual({ sensor: "in:goal" });
    expect(buildExpr({ kind: "outside", region: "critical" })).toEqual({
      if: { sensor: "in:critical" },
      then: 0,
      else: 1,
    });
    expect(buildExpr({ kind: "prediction", demon: "colour" })).toEqual({ prediction: "colour" });
  });

  it("parses raw JSON and names a syntax error", () => {
    expect(buildExpr({ kind: "json", text: '{"mul": [100, {"sensor": "color:lamp"}]}' })).toEqual({
      mul: [100, { sensor: "color:lamp" }],
    });
    expect(() => buildExpr({ kind: "json", text: "{mul: " })).toThrow(ExprSyntaxError);
    expect(() => buildExpr({ kind: "json", text: "  " })).toThrow(/write an expression/);
  });
});

describe("describeExpr", () => {
  const roundTrips: ExprChoice[] = [
    { kind: "constant", value: 1 },
    { kind: "sensor", sensor: "color:lamp" },
    { kind: "inside", region: "goal" },
    { kind: "outside", region: "critical" },
    { kind: "prediction", demon: "base" },
    { kind: "json", text: '{"if":{"sensor":"in:goal"},"then":1,"else":{"if":{"sensor":"in:pit"},"then":-1,"else":0}}' },
  ];
  it.each(roundTrips)("gives back the choice that built it: $kind", (choice) => {
    expect(describeExpr(buildExpr(choice))).toEqual(choice);
  });

  it("reads anything uncommon as JSON", () => {
    expect(describeExpr({ if: { sensor: "in:goal" }, then: 1, else: 0 })).toEqual({
      kind: "json",
      text: '{"if":{"sensor":"in:goal"},"then":1,"else":0}',
    });
    expect(describeExpr({ sensor: "in:goal", extra: 1 }).kind).toBe("json");
  });

  it("writes one line for tables", () => {
    expect(exprText({ if: { sensor: "in:critical" }, then: 0, else: 1 })).toBe("in:critical ? 0 : 1");
    expect(exprText({ prediction: "colour" })).toBe("prediction of colour");
    expect(exprText(-0.01)).toBe("-0.01");
  });
});
