/**
 * One expression of a question (cumulant, outcome or continuation): a choice of the common forms
 * (a constant, a sensor from the world's sensors, "1 inside region X else 0", "0 inside region X
 * else 1", another demon's prediction) or raw JSON for anything else.
 */
import type { Expr } from "../api/types";
import {
  EXPR_KIND_LABELS,
  type ExprChoice,
  type ExprKind,
  ExprSyntaxError,
  buildExpr,
  describeExpr,
} from "../lib/expr";
import { InputError } from "../lib/input-error";
import { readNumber } from "../lib/parse";
import { GLOSSARY, type Term } from "../lib/glossary";
import { h, options, replaceChildren, uid } from "../ui/dom";
import { type FormErrors, termLabel } from "../ui/legacy-form";

export interface ExprContext {
  sensors: string[];
  regions: string[];
  demons: string[];
}

export interface ExprInput {
  element: HTMLElement;
  read: () => Expr;
  set: (expr: unknown) => void;
  setContext: (context: ExprContext) => void;
}

const KINDS = Object.keys(EXPR_KIND_LABELS) as ExprKind[];

export function exprInput(label: string, path: string, errors: FormErrors, initial: unknown): ExprInput {
  const id = uid(path);
  const kind = h(
    "select",
    { id, "data-field": `${path}-kind` },
    options(KINDS.map((k) => [k, EXPR_KIND_LABELS[k]] as const)),
  );
  const constant = h("input", {
    type: "number",
    step: "any",
    "aria-label": `${label}: constant`,
    "data-field": `${path}-constant`,
  });
  const sensor = h("select", { "aria-label": `${label}: sensor`, "data-field": `${path}-sensor` });
  const region = h("select", { "aria-label": `${label}: region`, "data-field": `${path}-region` });
  const demon = h("select", { "aria-label": `${label}: demon`, "data-field": `${path}-demon` });
  const json = h("textarea", {
    rows: 2,
    spellcheck: "false",
    "aria-label": `${label}: JSON`,
    "data-field": `${path}-json`,
  });
  const controls: Record<ExprKind, HTMLElement> = {
    constant,
    sensor,
    inside: region,
    outside: region,
    prediction: demon,
    json,
  };
  let context: ExprContext = { sensors: [], regions: [], demons: [] };

  const show = () => {
    for (const control of new Set(Object.values(controls)))
      control.hidden = control !== controls[kind.value as ExprKind];
  };
  kind.addEventListener("change", show);

  // Keep a value that the lists do not hold (a demon loaded from elsewhere), rather than lose it.
  const fillSelect = (select: HTMLSelectElement, items: string[], value: string) => {
    const all = value && !items.includes(value) ? [...items, value] : items;
    replaceChildren(select, options(all, value || all[0]));
  };

  const set = (expr: unknown) => {
    const choice = describeExpr(expr);
    kind.value = choice.kind;
    constant.value = choice.kind === "constant" ? String(choice.value) : "0";
    fillSelect(sensor, context.sensors, choice.kind === "sensor" ? choice.sensor : sensor.value);
    fillSelect(
      region,
      context.regions,
      choice.kind === "inside" || choice.kind === "outside" ? choice.region : region.value,
    );
    fillSelect(demon, context.demons, choice.kind === "prediction" ? choice.demon : demon.value);
    json.value = choice.kind === "json" ? choice.text : JSON.stringify(expr);
    show();
  };

  const setContext = (next: ExprContext) => {
    context = next;
    fillSelect(sensor, next.sensors, next.sensors.includes(sensor.value) ? sensor.value : "");
    fillSelect(region, next.regions, next.regions.includes(region.value) ? region.value : "");
    fillSelect(demon, next.demons, next.demons.includes(demon.value) ? demon.value : "");
  };

  const read = (): Expr => {
    const choice = currentChoice(kind.value as ExprKind, { constant, sensor, region, demon, json });
    try {
      return buildExpr(choice);
    } catch (error) {
      if (error instanceof ExprSyntaxError) throw new InputError(path, error.message);
      throw error;
    }
  };

  const message = errors.register(path, kind);
  set(initial);
  const element = h(
    "div",
    { class: "field expr" },
    path in GLOSSARY ? termLabel(label, id, path as Term) : h("label", { for: id }, label),
    h(
      "div",
      { class: "expr-row", oninput: () => errors.clearField(path), onchange: () => errors.clearField(path) },
      kind,
      constant,
      sensor,
      region,
      demon,
      json,
    ),
    message,
  );
  return { element, read, set, setContext };
}

interface ExprControls {
  constant: HTMLInputElement;
  sensor: HTMLSelectElement;
  region: HTMLSelectElement;
  demon: HTMLSelectElement;
  json: HTMLTextAreaElement;
}

function currentChoice(kind: ExprKind, c: ExprControls): ExprChoice {
  switch (kind) {
    case "constant":
      return { kind, value: readNumber(c.constant.value) };
    case "sensor":
      return { kind, sensor: c.sensor.value };
    case "inside":
    case "outside":
      return { kind, region: c.region.value };
    case "prediction":
      return { kind, demon: c.demon.value };
    case "json":
      return { kind, text: c.json.value };
  }
}
