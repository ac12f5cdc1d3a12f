/**
 * Pydantic's validation messages in plain words. A 422 names each problem's kind (`type`) and its limits
 * (`ctx`); the user reads what to type instead ("a number from 0 to 1"), not the validator's phrasing
 * ("Input should be less than or equal to 1"). Kinds not listed keep the server's message, without
 * pydantic's "Value error, " prefix (the project's own checks already speak plainly).
 */
import type { ValidationProblem } from "../api/types";

type Context = Record<string, unknown>;

const NAME_PATTERN = "^[A-Za-z_][A-Za-z0-9_.-]*$";

function limit(ctx: Context, key: string): string {
  const value = ctx[key];
  return typeof value === "number" ? value.toLocaleString("en-US") : String(value);
}

function plural(count: unknown, word: string): string {
  return `${String(count)} ${word}${count === 1 ? "" : "s"}`;
}

const BY_TYPE: Record<string, (ctx: Context) => string> = {
  missing: () => "Required: fill this in.",
  extra_forbidden: () => "Not a field the server knows: remove it (check its spelling).",
  string_pattern_mismatch: (ctx) =>
    ctx.pattern === NAME_PATTERN
      ? "Use letters, digits, _ . or - (no spaces), starting with a letter or _."
      : `Does not have the expected form (${String(ctx.pattern)}).`,
  string_too_short: (ctx) => `Too short: at least ${plural(ctx.min_length, "character")}.`,
  string_too_long: (ctx) => `Too long: at most ${plural(ctx.max_length, "character")}.`,
  too_short: (ctx) => `Needs at least ${plural(ctx.min_length, "item")}.`,
  too_long: (ctx) => `Takes at most ${plural(ctx.max_length, "item")}.`,
  greater_than: (ctx) => `Must be more than ${limit(ctx, "gt")}.`,
  greater_than_equal: (ctx) => `Must be ${limit(ctx, "ge")} or more.`,
  less_than: (ctx) => `Must be less than ${limit(ctx, "lt")}.`,
  less_than_equal: (ctx) => `Must be ${limit(ctx, "le")} or less.`,
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
  literal_error: (ctx) => `Choose one of: ${String(ctx.expected).replace(/'/g, "")}.`,
  enum: (ctx) => `Choose one of: ${String(ctx.expected).replace(/'/g, "")}.`,
  json_invalid: () => "Not valid JSON.",
  union_tag_invalid: (ctx) => `Unknown kind: choose one of ${String(ctx.expected_tags).replace(/'/g, "")}.`,
  union_tag_not_found: (ctx) => `Say which kind it is (the "${String(ctx.discriminator).replace(/'/g, "")}" key).`,
};

/** Pydantic prefixes custom checks with "Value error, "; the user needs only what follows. */
export function cleanMessage(msg: string): string {
  return msg.replace(/^(Value|Assertion) error, /, "");
}

/** The problem in plain words: by its kind when known, else the server's message. */
export function humanMessage(problem: Pick<ValidationProblem, "msg" | "type"> & { ctx?: unknown }): string {
  const describe = BY_TYPE[problem.type];
  const ctx = (problem.ctx ?? {}) as Context;
  return describe ? describe(ctx) : cleanMessage(problem.msg);
}
