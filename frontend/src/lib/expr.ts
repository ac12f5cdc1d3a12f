/**
 * The question language made easy: common expressions as choices, anything else as raw JSON.
 *
 * `buildExpr` turns a choice into the API's `Expr`; `describeExpr` recognises an `Expr` as the
 * simplest choice that gives it back (so a demon can be loaded into the form and saved unchanged).
 */
import type { Expr } from "../api/types";

export type ExprChoice =
  | { kind: "constant"; value: number }
  | { kind: "sensor"; sensor: string }
  | { kind: "inside"; region: string } // 1 inside the region, else 0
  | { kind: "outside"; region: string } // 0 inside the region, else 1
  | { kind: "prediction"; demon: string }
  | { kind: "json"; text: string };

export type ExprKind = ExprChoice["kind"];

export const EXPR_KIND_LABELS: Record<ExprKind, string> = {
  constant: "constant",
  sensor: "sensor",
  inside: "1 in region, else 0",
  outside: "0 in region, else 1",
  prediction: "a demon's prediction",
  json: "JSON expression",
};

/** Raw JSON that does not parse: the form shows it at the expression's field. */
export class ExprSyntaxError extends Error {
  constructor(message: string) {
    super(message);
    this.name = "ExprSyntaxError";
  }
}

export const insideSensor = (region: string): string => `in:${region}`;

export function buildExpr(choice: ExprChoice): Expr {
  switch (choice.kind) {
    case "constant":
      return choice.value;
    case "sensor":
      return { sensor: choice.sensor };
    case "inside":
      // The in:<region> sensor is 1 inside and 0 outside already.
      return { sensor: insideSensor(choice.region) };
    case "outside":
      return { if: { sensor: insideSensor(choice.region) }, then: 0, else: 1 };
    case "prediction":
      return { prediction: choice.demon };
    case "json":
      return parseExprJson(choice.text);
  }
}

/** JSON text as an expression. The server checks its structure; here only the syntax. */
export function parseExprJson(text: string): Expr {
  if (text.trim() === "") throw new ExprSyntaxError('write an expression, e.g. 1 or {"sensor": "in:goal"}');
  try {
    return JSON.parse(text) as Expr;
  } catch (error) {
    throw new ExprSyntaxError(`not JSON: ${(error as Error).message}`);
  }
}

export function describeExpr(expr: unknown): ExprChoice {
  if (typeof expr === "number") return { kind: "constant", value: expr };
  const sensor = sensorOf(expr);
  if (sensor !== null) {
    return sensor.startsWith("in:") ? { kind: "inside", region: sensor.slice(3) } : { kind: "sensor", sensor };
  }
  if (isRecord(expr) && onlyKeys(expr, ["prediction"]) && typeof expr.prediction === "string") {
    return { kind: "prediction", demon: expr.prediction };
  }
  if (isRecord(expr) && onlyKeys(expr, ["if", "then", "else"]) && expr.then === 0 && expr.else === 1) {
    const tested = sensorOf(expr.if);
    if (tested?.startsWith("in:")) return { kind: "outside", region: tested.slice(3) };
  }
  return { kind: "json", text: JSON.stringify(expr) };
}

/** A one-line reading of an expression for tables ("in:goal ? 0 : 1"). */
export function exprText(expr: unknown): string {
  const choice = describeExpr(expr);
  switch (choice.kind) {
    case "constant":
      return String(choice.value);
    case "sensor":
      return choice.sensor;
    case "inside":
      return insideSensor(choice.region);
    case "outside":
      return `${insideSensor(choice.region)} ? 0 : 1`;
    case "prediction":
      return `prediction of ${choice.demon}`;
    case "json":
      return choice.text;
  }
}

function sensorOf(expr: unknown): string | null {
  return isRecord(expr) && onlyKeys(expr, ["sensor"]) && typeof expr.sensor === "string" ? expr.sensor : null;
}

function isRecord(value: unknown): value is Record<string, unknown> {
  return typeof value === "object" && value !== null && !Array.isArray(value);
}

function onlyKeys(record: Record<string, unknown>, keys: string[]): boolean {
  const present = Object.keys(record);
  return present.length === keys.length && keys.every((key) => key in record);
}
