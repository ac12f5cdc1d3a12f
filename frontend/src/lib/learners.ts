/**
 * The learners a demon can choose, as the server's registry declares them (GET /api/learners: each
 * learner module of the engine registers its name, one-line explanation, parameters and needs; the
 * query cache holds them, `reads.learners`), and the step-size modes with their explanations (README
 * "Learners and step sizes"). Which combinations are defined stays the server's to say (a 422 names
 * the field and the papers).
 */
import type { components } from "../api/schema";
import type { DemonSpec } from "../api/types";

type StepSize = NonNullable<DemonSpec["step_size"]>;
export type LearnerInfo = components["schemas"]["LearnerOut"];

export const STEP_SIZE_TEXT: Record<StepSize, string> = {
  constant: "constant: α as given",
  autostep: "autostep (TD only): per-weight, tuned online, never overshoots",
  tidbd: "tidbd (TD only): per-weight, tuned online by meta-descent",
};

/** [value, label] pairs of the registry's learners, for a select ("gq" alone until they arrive). */
export function learnerChoices(infos: readonly LearnerInfo[]): (readonly [string, string])[] {
  if (infos.length === 0) return [["gq", "gq"]];
  return infos.map((info) => [info.name, `${info.name}: ${info.text}`] as const);
}

/**
 * Why a learner takes no λ, or null when it learns with traces (or is not known yet): the registry's `traces`
 * is false for a learner with a published form at λ 0 only (gtd1, the original GTD): the server keeps it at 0.
 */
export function noTracesWhy(infos: readonly LearnerInfo[], learner: string): string | null {
  const info = infos.find((i) => i.name === learner);
  if (!info || info.traces) return null;
  return `${info.name} learns with λ 0 only: its paper gives no form with eligibility traces`;
}

/** [value, label] pairs for a select, in the order of the texts. */
export function choices<K extends string>(texts: Record<K, string>): (readonly [K, string])[] {
  return (Object.keys(texts) as K[]).map((key) => [key, texts[key]] as const);
}
