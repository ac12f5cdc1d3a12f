/**
 * A demon's target policy: its kind and the fields that kind needs (probabilities of a fixed policy,
 * a softmax temperature, an epsilon, the demon an `of` policy follows).
 */
import type { PolicySpec } from "../api/types";
import { formatList, readNumber, readNumberList } from "../lib/parse";
import { h, options, replaceChildren } from "../ui/dom";
import { type FormErrors, field, numberInput, textInput } from "../ui/legacy-form";

type PolicyKind = PolicySpec["kind"];

const KINDS: readonly (readonly [PolicyKind, string])[] = [
  ["uniform", "uniform"],
  ["fixed", "fixed"],
  ["of", "follow a demon"],
  ["greedy", "greedy (control)"],
  ["softmax", "softmax (control)"],
  ["epsilon_greedy", "ε-greedy (control)"],
];

export interface PolicyFields {
  element: HTMLElement;
  read: () => PolicySpec;
  set: (policy: PolicySpec) => void;
  setDemons: (demons: string[]) => void;
}

export function policyFields(errors: FormErrors): PolicyFields {
  const kind = h("select", { "data-field": "policy-kind" }, options(KINDS, "of"));
  const demon = h("select", { "data-field": "policy-demon" });
  const probabilities = textInput("0.25, 0.25, 0.25, 0.25", { "data-field": "policy-probabilities" });
  const temperature = numberInput(1, { "data-field": "policy-temperature" });
  const epsilon = numberInput(0.1, { "data-field": "policy-epsilon" });

  const fields = {
    of: field("Follows", demon, { path: "policy.demon", errors }),
    fixed: field("Probabilities", probabilities, {
      path: "policy.probabilities",
      errors,
      hint: "up, down, left, right",
    }),
    softmax: field("Temperature", temperature, { path: "policy.temperature", errors }),
    epsilon_greedy: field("Epsilon", epsilon, { path: "policy.epsilon", errors }),
  };
  const show = () => {
    for (const [name, element] of Object.entries(fields)) element.hidden = name !== kind.value;
  };
  kind.addEventListener("change", show);
  show();

  const setDemons = (demons: string[]) => {
    const chosen = demons.includes(demon.value) ? demon.value : demons[0];
    replaceChildren(demon, options(demons, chosen));
  };

  const set = (policy: PolicySpec) => {
    kind.value = policy.kind;
    if (policy.demon) {
      if (![...demon.options].some((o) => o.value === policy.demon))
        demon.append(h("option", { value: policy.demon }, policy.demon));
      demon.value = policy.demon;
    }
    probabilities.value = formatList(policy.probabilities ?? [0.25, 0.25, 0.25, 0.25]);
    temperature.value = String(policy.temperature ?? 1);
    epsilon.value = String(policy.epsilon ?? 0.1);
    show();
  };

  // Only the fields of the chosen kind are sent; the server fills in its defaults for the others.
  const read = (): PolicySpec => {
    const chosen = kind.value as PolicyKind;
    const policy = { kind: chosen } as PolicySpec;
    if (chosen === "of") policy.demon = demon.value;
    if (chosen === "fixed") policy.probabilities = readNumberList(probabilities.value);
    if (chosen === "softmax") policy.temperature = readNumber(temperature.value);
    if (chosen === "epsilon_greedy") policy.epsilon = readNumber(epsilon.value);
    return policy;
  };

  const element = h(
    "div",
    { class: "policy" },
    h(
      "div",
      { class: "row" },
      field("Target policy", kind, { path: "policy.kind", errors, term: "policy" }),
      ...Object.values(fields),
    ),
    errors.register("policy", null),
  );
  return { element, read, set, setDemons };
}
