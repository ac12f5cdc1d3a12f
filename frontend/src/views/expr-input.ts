/**
 * One expression of a question (cumulant, outcome or continuation): a choice of the common forms
 * (a constant, a sensor from the world's sensors, "1 inside region X else 0", "0 inside region X
 * else 1", another demon's prediction) or raw JSON for anything else.
 */
import { html } from "lit-html";
import { ifDefined } from "lit-html/directives/if-defined.js";
import { live } from "lit-html/directives/live.js";
import type { Expr } from "../api/types";
import {
  EXPR_KIND_LABELS,
  type ExprChoice,
  type ExprKind,
  ExprSyntaxError,
  buildExpr,
  describeExpr,
} from "../lib/expr";
import { GLOSSARY, type Term } from "../lib/glossary";
import { InputError } from "../lib/input-error";
import { readNumber } from "../lib/parse";
import { type FormErrors, bound, errorSlot, termLabel } from "../ui/form";
import { choices } from "../ui/html";

export interface ExprContext {
  sensors: string[];
  regions: string[];
  demons: string[];
}

/** An expression as the form holds it: the kind chosen and each kind's text. */
export interface ExprText extends Record<string, string> {
  kind: ExprKind;
  constant: string;
  sensor: string;
  region: string;
  demon: string;
  json: string;
}

const KINDS = (Object.keys(EXPR_KIND_LABELS) as ExprKind[]).map((k) => [k, EXPR_KIND_LABELS[k]] as const);

/** The form's text of `expr` (the other kinds keep what `previous` had). */
export function exprText(expr: unknown, previous?: ExprText): ExprText {
  const choice = describeExpr(expr);
  return {
    kind: choice.kind,
    constant: choice.kind === "constant" ? String(choice.value) : "0",
    sensor: choice.kind === "sensor" ? choice.sensor : (previous?.sensor ?? ""),
    region: choice.kind === "inside" || choice.kind === "outside" ? choice.region : (previous?.region ?? ""),
    demon: choice.kind === "prediction" ? choice.demon : (previous?.demon ?? ""),
    json: choice.kind === "json" ? choice.text : JSON.stringify(expr),
  };
}

/** The lists have changed (another run): a choice they no longer hold gives way to their first. */
export function fitContext(text: ExprText, context: ExprContext): void {
  if (!context.sensors.includes(text.sensor)) text.sensor = context.sensors[0] ?? "";
  if (!context.regions.includes(text.region)) text.region = context.regions[0] ?? "";
  if (!context.demons.includes(text.demon)) text.demon = context.demons[0] ?? "";
}

/** The expression the text describes; throws InputError (at `path`) for JSON that does not parse. */
export function readExpr(text: ExprText, path: string): Expr {
  const choice: ExprChoice =
    text.kind === "constant"
      ? { kind: "constant", value: readNumber(text.constant) }
      : text.kind === "sensor"
        ? { kind: "sensor", sensor: text.sensor }
        : text.kind === "inside" || text.kind === "outside"
          ? { kind: text.kind, region: text.region }
          : text.kind === "prediction"
            ? { kind: "prediction", demon: text.demon }
            : { kind: "json", text: text.json };
  try {
    return buildExpr(choice);
  } catch (error) {
    if (error instanceof ExprSyntaxError) throw new InputError(path, error.message);
    throw error;
  }
}

/** Keep a value that the list does not hold (a demon loaded from elsewhere), rather than lose it. */
const withValue = (items: string[], value: string) => (value && !items.includes(value) ? [...items, value] : items);

export function exprInput(
  label: string,
  path: string,
  text: ExprText,
  context: ExprContext,
  errors: FormErrors,
  redraw: () => void,
) {
  const id = `${errors.id}-${path}`;
  const hiddenUnless = (kind: ExprKind | ExprKind[]) => ![kind].flat().includes(text.kind);
  const list = (key: "sensor" | "region" | "demon", items: string[], name: string, hidden: boolean) =>
    html`<select
      aria-label="${label}: ${name}"
      data-field="${path}-${key}"
      data-path=${path}
      ?hidden=${hidden}
      @change=${bound(text, key).onChange}
    >
      ${choices(withValue(items, text[key]), text[key])}
    </select>`;
  return html`<div class="field expr">
    ${path in GLOSSARY ? termLabel(label, id, path as Term) : html`<label for=${id}>${label}</label>`}
    <div class="expr-row">
      <select
        id=${id}
        data-field="${path}-kind"
        data-path=${path}
        aria-describedby="${id}-error"
        aria-invalid=${ifDefined(errors.at(path).length > 0 ? "true" : undefined)}
        @change=${bound(text, "kind", redraw).onChange}
      >
        ${choices(KINDS, text.kind)}
      </select>
      <input
        type="number"
        step="any"
        aria-label="${label}: constant"
        data-field="${path}-constant"
        data-path=${path}
        ?hidden=${hiddenUnless("constant")}
        .value=${live(text.constant)}
        @input=${bound(text, "constant").onInput}
      />
      ${list("sensor", context.sensors, "sensor", hiddenUnless("sensor"))}
      ${list("region", context.regions, "region", hiddenUnless(["inside", "outside"]))}
      ${list("demon", context.demons, "demon", hiddenUnless("prediction"))}
      <textarea
        rows="2"
        spellcheck="false"
        aria-label="${label}: JSON"
        data-field="${path}-json"
        data-path=${path}
        ?hidden=${hiddenUnless("json")}
        .value=${live(text.json)}
        @input=${bound(text, "json").onInput}
      ></textarea>
    </div>
    ${errorSlot(errors, path, `${id}-error`)}
  </div>`;
}
