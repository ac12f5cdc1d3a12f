/**
 * The learners and step-size modes a demon can choose, each with its one-line explanation (README
 * "Learners and step sizes"). Keyed by the API's own types, so a learner the server adds and the
 * dashboard does not explain fails to compile. Which combinations are defined stays the server's to say
 * (a 422 names the field and the papers).
 */
import type { DemonSpec } from "../api/types";

type Learner = DemonSpec["learner"] & string;
type StepSize = NonNullable<DemonSpec["step_size"]>;

export const LEARNER_TEXT: Record<Learner, string> = {
  gq: "GQ(λ): action values",
  gtd: "GTD(λ): state values",
  td: "TD(λ): state values, no correction",
  true_online_td: "true online TD(λ): the forward view exactly, less step-size sensitive",
  true_online_gtd: "true online GTD(λ): the same, with GTD's correction",
  etd: "emphatic TD(λ): stable off-policy, no second weight vector",
};

export const STEP_SIZE_TEXT: Record<StepSize, string> = {
  constant: "constant: α as given",
  autostep: "autostep (TD only): per-weight, tuned online, never overshoots",
  tidbd: "tidbd (TD only): per-weight, tuned online by meta-descent",
};

/** [value, label] pairs for a select, in the order above. */
export function choices<K extends string>(texts: Record<K, string>): (readonly [K, string])[] {
  return (Object.keys(texts) as K[]).map((key) => [key, texts[key]] as const);
}
