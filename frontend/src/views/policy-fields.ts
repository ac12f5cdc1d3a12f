/**
 * A demon's target policy: its kind and the fields that kind needs (probabilities of a fixed policy,
 * a softmax temperature, an epsilon, the demon an `of` policy follows).
 */
import { html } from "lit-html";
import type { PolicySpec } from "../api/types";
import { formatList, readNumber, readNumberList } from "../lib/parse";
import { type FormErrors, bound, errorSlot, numberField, selectField, textField } from "../ui/form";
import { choices } from "../ui/html";

type PolicyKind = PolicySpec["kind"];

const KINDS: readonly (readonly [PolicyKind, string])[] = [
  ["uniform", "uniform"],
  ["fixed", "fixed"],
  ["of", "follow a demon"],
  ["greedy", "greedy (control)"],
  ["softmax", "softmax (control)"],
  ["epsilon_greedy", "ε-greedy (control)"],
];

/** A target policy as the form holds it. */
export interface PolicyText extends Record<string, string> {
  kind: PolicyKind;
  demon: string;
  probabilities: string;
  temperature: string;
  epsilon: string;
}

export function policyText(policy: PolicySpec, previous?: PolicyText): PolicyText {
  return {
    kind: policy.kind,
    demon: policy.demon ?? previous?.demon ?? "",
    probabilities: formatList(policy.probabilities ?? [0.25, 0.25, 0.25, 0.25]),
    temperature: String(policy.temperature ?? 1),
    epsilon: String(policy.epsilon ?? 0.1),
  };
}

// Only the fields of the chosen kind are sent; the server fills in its defaults for the others.
export function readPolicy(text: PolicyText): PolicySpec {
  const policy = { kind: text.kind } as PolicySpec;
  if (text.kind === "of") policy.demon = text.demon;
  if (text.kind === "fixed") policy.probabilities = readNumberList(text.probabilities);
  if (text.kind === "softmax") policy.temperature = readNumber(text.temperature);
  if (text.kind === "epsilon_greedy") policy.epsilon = readNumber(text.epsilon);
  return policy;
}

export function policyFields(text: PolicyText, demons: string[], errors: FormErrors, redraw: () => void) {
  // A demon it follows that the run does not hold (loaded from elsewhere) is kept, not lost.
  const followed = text.demon && !demons.includes(text.demon) ? [...demons, text.demon] : demons;
  return html`<div class="policy">
    <div class="row">
      ${selectField(
        { label: "Target policy", path: "policy.kind", errors, term: "policy" },
        { field: "policy-kind", ...bound(text, "kind", redraw) },
        choices(KINDS, text.kind),
      )}
      ${selectField(
        { label: "Follows", path: "policy.demon", errors, hidden: text.kind !== "of" },
        { field: "policy-demon", ...bound(text, "demon") },
        choices(followed, text.demon),
      )}
      ${textField(
        {
          label: "Probabilities",
          path: "policy.probabilities",
          errors,
          hint: "up, down, left, right",
          hidden: text.kind !== "fixed",
        },
        { field: "policy-probabilities", ...bound(text, "probabilities") },
      )}
      ${numberField(
        { label: "Temperature", path: "policy.temperature", errors, hidden: text.kind !== "softmax" },
        { field: "policy-temperature", ...bound(text, "temperature") },
      )}
      ${numberField(
        { label: "Epsilon", path: "policy.epsilon", errors, hidden: text.kind !== "epsilon_greedy" },
        { field: "policy-epsilon", ...bound(text, "epsilon") },
      )}
    </div>
    ${errorSlot(errors, "policy")}
  </div>`;
}
