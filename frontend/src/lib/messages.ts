/**
 * Pydantic's validation messages in plain words. A 422 names each problem's kind (`type`) and its limits
 * (`ctx`); the user reads what to type instead ("a number from 0 to 1"), not the validator's phrasing
 * ("Input should be less than or equal to 1"). Kinds not listed keep the server's message, without
 * pydantic's "Value error, " prefix (the project's own checks already speak plainly).
 */
import type { ValidationProblem } from "../api/types";

type Context = Record<string, unknown>;

const NAME_PATTERN = "^[A-Za-z_][A-Za-z0-9_.-]*$";

// Some problems reach the dashboard without their `ctx` (the server's own re-raised checks): the limit
// is then read from the end of pydantic's message ("... greater than or equal to 1").
function limit(ctx: Context, key: string, msg: string): string | null {
  const value = ctx[key] ?? Number(/(-?\d+(\.\d+)?(e[+-]?\d+)?)\D*$/i.exec(msg)?.[1]);
  if (typeof value === "number" && Number.isFinite(value)) return value.toLocaleString("en-US");
  return null;
}

function count(ctx: Context, key: string, msg: string, word: string): string | null {
  const value = limit(
    ctx,
    key,
    msg
      .replace(/ after validation.*$/, "")
      .replace(/ items?$/, "")
      .replace(/ characters?$/, ""),
  );
  return value === null ? null : `${value} ${word}${value === "1" ? "" : "s"}`;
}

type Describe = (ctx: Context, msg: string) => string | null;

const BY_TYPE: Record<string, Describe> = {
  missing: () => "Required: fill this in.",
  extra_forbidden: () => "Not a field the server knows: remove it (check its spelling).",
  string_pattern_mismatch: (ctx, msg) =>
    ctx.pattern === NAME_PATTERN || msg.includes(NAME_PATTERN)
      ? "Use letters, digits, _ . or - (no spaces), starting with a letter or _."
      : null,
  string_too_short: (ctx, msg) => maybe(count(ctx, "min_length", msg, "character"), (n) => `Too short: at least ${n}.`),
  string_too_long: (ctx, msg) => maybe(count(ctx, "max_length", msg, "character"), (n) => `Too long: at most ${n}.`),
  too_short: (ctx, msg) => maybe(count(ctx, "min_length", msg, "item"), (n) => `Needs at least ${n}.`),
  too_long: (ctx, msg) => maybe(count(ctx, "max_length", msg, "item"), (n) => `Takes at most ${n}.`),
  greater_than: (ctx, msg) => maybe(limit(ctx, "gt", msg), (n) => `Must be more than ${n}.`),
  greater_than_equal: (ctx, msg) => maybe(limit(ctx, "ge", msg), (n) => `Must be ${n} or more.`),
  less_than: (ctx, msg) => maybe(limit(ctx, "lt", msg), (n) => `Must be less than ${n}.`),
  less_than_equal: (ctx, msg) => maybe(limit(ctx, "le", msg), (n) => `Must be ${n} or less.`),
  float_parsing: () => "Must be a number.",
  float_type: () => "Must be a number.",
  int_parsing: () => "Must be a whole number.",
  int_type: () => "Must be a whole number.",
  int_from_float: () => "Must be a whole number (no decimals).",
  finite_number: () => "Must be a finite number.",
  bool_parsing: () => "Must be true or false.",
  string_type: () => "Must be text.",
  list_type: () => "Must be a list.",
  dict_type: () => "Must be an object.",
  model_type: () => "Must be an object.",
  literal_error: (ctx) => maybe(ctx.expected, (e) => `Choose one of: ${String(e).replace(/'/g, "")}.`),
  enum: (ctx) => maybe(ctx.expected, (e) => `Choose one of: ${String(e).replace(/'/g, "")}.`),
  json_invalid: () => "Not valid JSON.",
  union_tag_invalid: (ctx) =>
    maybe(ctx.expected_tags, (e) => `Unknown kind: choose one of ${String(e).replace(/'/g, "")}.`),
  union_tag_not_found: (ctx) =>
    maybe(ctx.discriminator, (d) => `Say which kind it is (the "${String(d).replace(/'/g, "")}" key).`),
};

function maybe<T>(value: T | null | undefined, say: (value: T) => string): string | null {
  return value === null || value === undefined ? null : say(value);
}

/** Pydantic prefixes custom checks with "Value error, "; the user needs only what follows. */
export function cleanMessage(msg: string): string {
  return msg.replace(/^(Value|Assertion) error, /, "");
}

/** The problem in plain words: by its kind when known, else the server's message. */
export function humanMessage(problem: Pick<ValidationProblem, "msg" | "type"> & { ctx?: unknown }): string {
  const ctx = (problem.ctx ?? {}) as Context;
  return BY_TYPE[problem.type]?.(ctx, problem.msg) ?? cleanMessage(problem.msg);
}
