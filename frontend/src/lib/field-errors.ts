/**
 * From a 422's problems to the form fields they concern.
 *
 * FastAPI locates a problem with `loc`, e.g. ["body", "regions", 0, "rect"]. Forms register their
 * fields under dotted paths ("regions.0.rect"); a problem goes to the field with the longest path
 * that is a prefix of its location. Problems of a whole object (the server's cross-field checks,
 * e.g. ["body"]: "demon 'x': continuation can take values in [2, 2]") go to the one child field the
 * message names, if it names exactly one; the rest are shown for the form as a whole.
 */
import type { ValidationProblem } from "../api/types";
import { humanMessage } from "./messages";

export interface ProblemPlacement {
  /** field path -> messages for it */
  byField: Map<string, string[]>;
  /** messages that concern no registered field */
  general: string[];
}

const SOURCES = new Set(["body", "query", "path", "header", "cookie"]);
const SCALAR_TAGS = new Set(["float", "int", "str", "bool", "list", "dict", "none"]);

/**
 * The field path of a location: without the request part ("body", "query") and without the tags
 * pydantic adds for union members ("RunTemplate", "SensorExpr", "float", "function-after[...]").
 */
export function locationPath(loc: readonly (string | number)[]): (string | number)[] {
  const rest = loc.length > 0 && SOURCES.has(String(loc[0])) ? loc.slice(1) : [...loc];
  return rest.filter((part) => typeof part === "number" || !isUnionTag(part));
}

function isUnionTag(part: string): boolean {
  return /^[A-Z]/.test(part) || SCALAR_TAGS.has(part) || part.includes("[");
}

export function placeProblems(problems: readonly ValidationProblem[], fields: Iterable<string>): ProblemPlacement {
  const known = new Set(fields);
  const byField = new Map<string, string[]>();
  const general: string[] = [];
  for (const problem of problems) {
    const message = humanMessage(problem);
    const field = fieldFor(locationPath(problem.loc), message, known);
    if (field === null) {
      general.push(message);
      continue;
    }
    const messages = byField.get(field) ?? [];
    if (!messages.includes(message)) messages.push(message); // union members repeat themselves
    byField.set(field, messages);
  }
  return { byField, general };
}

function fieldFor(path: (string | number)[], message: string, known: Set<string>): string | null {
  for (let length = path.length; length >= 0; length--) {
    const prefix = path.slice(0, length).join(".");
    if (length > 0 && !known.has(prefix)) continue;
    // The deepest registered field holds the problem; if the location ends there, a child that
    // the message names is more precise still.
    if (length === path.length) {
      const named = namedChild(prefix, message, known);
      if (named !== null) return named;
    }
    if (length > 0) return prefix;
  }
  return null;
}

function namedChild(parent: string, message: string, known: Set<string>): string | null {
  const depth = parent === "" ? 1 : parent.split(".").length + 1;
  const children = [...known].filter(
    (field) => field.split(".").length === depth && (parent === "" || field.startsWith(`${parent}.`)),
  );
  const named = children.filter((field) => {
    const leaf = field.split(".").pop() ?? "";
    return new RegExp(`(^|[^\\w:])${escapeRegExp(leaf)}($|[^\\w:])`).test(message);
  });
  return named.length === 1 ? (named[0] ?? null) : null;
}

function escapeRegExp(text: string): string {
  return text.replace(/[.*+?^${}()|[\]\\]/g, "\\$&");
}
