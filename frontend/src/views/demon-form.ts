/** A demon as the demon editor (views/demon-editor.ts) holds it: text, filled from a spec and read back into one. */
import type { Demon, DemonSpec } from "../api/types";
import { readNumber, readOptionalNumber } from "../lib/parse";
import { type ExprText, exprText, readExpr } from "./expr-input";
import { type FeaturesText, featuresText, readFeatures } from "./features-fields";
import { type PolicyText, policyText, readPolicy } from "./policy-fields";

export const BLANK = "";
export const BLANK_MODE = "";

type Plain = "name" | "discount" | "learner" | "lambda" | "alpha" | "alpha_w" | "step_size" | "meta_step" | "reset";

export interface DemonText extends Record<Plain, string> {
  policy: PolicyText;
  cumulant: ExprText;
  outcome: ExprText;
  continuation: ExprText;
  features: FeaturesText;
}

const optional = (value: number | null | undefined) => (value == null ? "" : String(value));

/** The form's text of `demon` (the lists' choices of `previous` kept where the demon names none). */
export function demonText(demon: DemonSpec, previous?: DemonText): DemonText {
  return {
    name: demon.name,
    policy: policyText(demon.policy ?? { kind: "uniform", temperature: 1, epsilon: 0.1 }, previous?.policy),
    cumulant: exprText(demon.cumulant, previous?.cumulant),
    outcome: exprText(demon.outcome, previous?.outcome),
    continuation: exprText(demon.continuation, previous?.continuation),
    discount: String(demon.discount ?? 1),
    learner: demon.learner ?? "gq",
    features: featuresText(demon.features),
    lambda: optional(demon.lambda),
    alpha: optional(demon.alpha),
    alpha_w: optional(demon.alpha_w),
    step_size: demon.step_size ?? BLANK_MODE,
    meta_step: optional(demon.meta_step),
    reset: demon.reset ?? "never",
  };
}

/** The demon the form describes; optional fields left empty are left out (the run's defaults). */
export function readDemon(text: DemonText): DemonSpec {
  const spec: DemonSpec = {
    name: text.name.trim(),
    policy: readPolicy(text.policy),
    cumulant: readExpr(text.cumulant, "cumulant"),
    outcome: readExpr(text.outcome, "outcome"),
    continuation: readExpr(text.continuation, "continuation"),
    discount: readNumber(text.discount),
    learner: text.learner as DemonSpec["learner"],
    reset: text.reset as DemonSpec["reset"],
    lambda: readOptionalNumber(text.lambda),
    alpha: readOptionalNumber(text.alpha),
    alpha_w: readOptionalNumber(text.alpha_w),
    meta_step: readOptionalNumber(text.meta_step),
  };
  if (text.step_size !== BLANK_MODE) spec.step_size = text.step_size as NonNullable<DemonSpec["step_size"]>;
  const features = readFeatures(text.features);
  if (features) spec.features = features;
  return spec;
}

/** A question that reads well in a classroom: steps until the episode ends, under the behaviour's policy. */
export function blankDemon(demons: Demon[]): DemonSpec {
  const control = demons.find((d) => d.control);
  return {
    name: freeName(demons),
    policy: control
      ? { kind: "of", demon: control.name, temperature: 1, epsilon: 0.1 }
      : { kind: "uniform", temperature: 1, epsilon: 0.1 },
    cumulant: 1,
    outcome: 0,
    continuation: 1,
    discount: 1,
    learner: "gq",
    reset: "never",
  };
}

export function freeName(demons: Demon[]): string {
  const taken = new Set(demons.map((d) => d.name));
  for (let i = 1; ; i++) if (!taken.has(`demon${i}`)) return `demon${i}`;
}
