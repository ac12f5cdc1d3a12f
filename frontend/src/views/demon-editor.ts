/**
 * The demon editor: a question (target policy, cumulant, outcome, continuation, discount) and its
 * answer (features, learner, lambda, step sizes), added to the selected run while it runs
 * (POST /api/runs/{id}/demons). Lists of sensors, regions and demons come from the run's world.
 */
import { addDemon, notify } from "../app/actions";
import type { AppState, AppStore } from "../app/state";
import { ApiError } from "../api/client";
import type { Demon, DemonSpec } from "../api/types";
import { runLabel } from "../lib/format";
import { STEP_SIZE_TEXT, choices, learnerChoices, learners } from "../lib/learners";
import { readNumber, readOptionalNumber } from "../lib/parse";
import { regionNames, sensorNames } from "../lib/world";
import { h, options, replaceChildren } from "../ui/dom";
import { FormErrors, field, numberInput, textInput } from "../ui/form";
import { type ExprContext, exprInput } from "./expr-input";
import { featuresFields } from "./features-fields";
import { policyFields } from "./policy-fields";

const BLANK_MODE = "";
/** Step-size modes, and the run's default (README "Learners and step sizes"). */
const STEP_SIZES = [[BLANK_MODE, "the run's default"] as const, ...choices(STEP_SIZE_TEXT)];
const RESETS: readonly (readonly [DemonSpec["reset"], string])[] = [
  ["never", "never"],
  ["episode", "at every episode start"],
];
const BLANK = "";

export function demonEditor(store: AppStore): HTMLElement {
  const errors = new FormErrors();
  const runNote = h("p", { class: "run-note", "aria-live": "polite" });
  const template = h("select", { id: "demon-template" });
  const copy = h("button", { type: "button" }, "Copy into the form");
  const name = textInput("", { name: "name" });
  const policy = policyFields(errors);
  const cumulant = exprInput("Cumulant", "cumulant", errors, 1);
  const outcome = exprInput("Outcome", "outcome", errors, 0);
  const continuation = exprInput("Continuation", "continuation", errors, 1);
  const discount = numberInput(1, { name: "discount" });
  const learner = h("select", { name: "learner" }, options(["gq"], "gq"));
  learners()
    .then((infos) => replaceChildren(learner, ...options(learnerChoices(infos), learner.value)))
    .catch(() => undefined); // the server's answer comes with the next refresh; "gq" meanwhile
  const features = featuresFields(errors);
  const lambda = numberInput(null, { name: "lambda" });
  const alpha = numberInput(null, { name: "alpha" });
  const alphaW = numberInput(null, { name: "alpha_w" });
  const stepSize = h("select", { name: "step_size" }, options(STEP_SIZES, BLANK_MODE));
  const metaStep = numberInput(null, { name: "meta_step" });
  const reset = h("select", { name: "reset" }, options(RESETS, "never"));
  const submit = h("button", { type: "submit", class: "primary" }, "Add to run");
  const exprs = [cumulant, outcome, continuation];

  const fill = (demon: DemonSpec) => {
    errors.clear();
    name.value = demon.name;
    policy.set(demon.policy ?? { kind: "uniform", temperature: 1, epsilon: 0.1 });
    cumulant.set(demon.cumulant);
    outcome.set(demon.outcome);
    continuation.set(demon.continuation);
    discount.value = String(demon.discount ?? 1);
    learner.value = demon.learner ?? "gq";
    features.set(demon.features);
    lambda.value = demon.lambda == null ? "" : String(demon.lambda);
    alpha.value = demon.alpha == null ? "" : String(demon.alpha);
    alphaW.value = demon.alpha_w == null ? "" : String(demon.alpha_w);
    stepSize.value = demon.step_size ?? BLANK_MODE;
    metaStep.value = demon.meta_step == null ? "" : String(demon.meta_step);
    reset.value = demon.reset ?? "never";
  };

  /** The demon the form describes; optional fields left empty are left out (the run's defaults). */
  const read = (): DemonSpec => {
    const spec: DemonSpec = {
      name: name.value.trim(),
      policy: policy.read(),
      cumulant: cumulant.read(),
      outcome: outcome.read(),
      continuation: continuation.read(),
      discount: readNumber(discount.value),
      learner: learner.value as DemonSpec["learner"],
      reset: reset.value as DemonSpec["reset"],
      lambda: readOptionalNumber(lambda.value),
      alpha: readOptionalNumber(alpha.value),
      alpha_w: readOptionalNumber(alphaW.value),
      meta_step: readOptionalNumber(metaStep.value),
    };
    if (stepSize.value !== BLANK_MODE) spec.step_size = stepSize.value as NonNullable<DemonSpec["step_size"]>;
    const featureSpec = features.read();
    if (featureSpec) spec.features = featureSpec;
    return spec;
  };

  // The lists follow the selected run: its world's sensors and regions, its demons.
  const renderRun = (state: Readonly<AppState>) => {
    const { run, demons } = state;
    // Demons join created, running or paused runs; the server refuses finished and failed ones (409).
    const closed = run !== null && (run.status === "finished" || run.status === "failed");
    submit.disabled = run === null || closed;
    runNote.textContent =
      run === null
        ? "Select a run in the list (or launch one) to add demons to it."
        : closed
          ? `Run ${runLabel(run)} has ${run.status}: reset it, or pick another run, to add demons.`
          : `Adds the demon to run ${runLabel(run)} (${run.status}); it learns from the next step on.`;
    const world = run?.spec.world ?? {};
    const names = demons.map((d) => d.name);
    // The agent is never inside an obstacle: "1 in region" offers the regions it can enter.
    const regions = regionNames(world, ["terminal", "zone", "indicator"]);
    const context: ExprContext = { sensors: sensorNames(world), regions, demons: names };
    for (const expr of exprs) expr.setContext(context);
    policy.setDemons(names);
    replaceChildren(
      template,
      options([[BLANK, "a blank demon"], ...names.map((n) => [n, `a copy of ${n}`] as const)], template.value),
    );
    const learning = run?.spec.learning;
    lambda.placeholder = learning ? String(learning.lambda) : "";
    alpha.placeholder = learning ? String(learning.alpha) : "";
    alphaW.placeholder = learning ? String(learning.alpha_w) : "";
    metaStep.placeholder = learning?.meta_step != null ? String(learning.meta_step) : "";
    // Until the user edits, the form offers a blank demon that fits the run (it follows its control demon).
    if (!touched) {
      fill(blankDemon(demons));
      template.value = BLANK;
    } else if (!name.value) {
      name.value = freeName(demons);
    }
  };

  copy.addEventListener("click", () => {
    touched = true;
    const source = store.state.demons.find((d) => d.name === template.value);
    // A demon's spec comes back in the output form of the same model, which the form reads as input.
    fill(source ? { ...(source.spec as DemonSpec), name: `${source.name}_copy` } : blankDemon(store.state.demons));
  });

  const onSubmit = async (event: Event) => {
    event.preventDefault();
    errors.clear();
    const runId = store.state.selectedRunId;
    if (runId === null) return;
    const spec = errors.readOrShow(read);
    if (spec === null) return;
    submit.disabled = true;
    try {
      const demon = await addDemon(store, runId, spec);
      notify(store, `Added demon '${demon.name}' to the run.`);
      name.value = freeName(store.state.demons); // the rest stays, for a variant of the same question
    } catch (error) {
      if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
      else errors.showGeneral(error instanceof Error ? error.message : String(error));
    } finally {
      renderRun(store.state); // enables the button again where the run still takes demons
    }
  };

  let touched = false;
  fill(blankDemon([]));
  store.subscribe(renderRun, ["run", "demons"]);
  renderRun(store.state);

  return h(
    "form",
    {
      class: "demon-form",
      novalidate: true,
      onsubmit: onSubmit,
      oninput: () => (touched = true),
      "aria-label": "Demon",
    },
    runNote,
    h("div", { class: "row load-row" }, field("Start from", template), copy),
    field("Name", name, { path: "name", errors, term: "demon" }),
    h(
      "div",
      { class: "editor-columns" },
      h(
        "fieldset",
        {},
        h("legend", {}, "Question: what to predict"),
        policy.element,
        cumulant.element,
        outcome.element,
        continuation.element,
        field("Discount", discount, {
          path: "discount",
          errors,
          hint: "multiplies the continuation",
          term: "continuation",
        }),
      ),
      h(
        "fieldset",
        {},
        h("legend", {}, "Answer: how to learn it"),
        field("Learner", learner, { path: "learner", errors, term: "learner" }),
        features.element,
        h(
          "div",
          { class: "row" },
          field("λ (lambda)", lambda, { path: "lambda", errors, term: "lambda" }),
          field("α (alpha)", alpha, { path: "alpha", errors, term: "alpha" }),
          field("α_w (alpha_w)", alphaW, { path: "alpha_w", errors, term: "alphaW" }),
        ),
        h(
          "div",
          { class: "row" },
          field("Step size", stepSize, { path: "step_size", errors, term: "stepSize" }),
          field("Meta step", metaStep, { path: "meta_step", errors, hint: "autostep's μ, tidbd's θ" }),
        ),
        field("Forget the weights", reset, { path: "reset", errors }),
        h(
          "p",
          { class: "hint" },
          "Empty λ and step sizes take the run's (shown greyed). Step sizes are divided by the number of active features.",
        ),
      ),
    ),
    errors.general,
    h("div", { class: "actions" }, submit),
  );
}

/** A question that reads well in a classroom: steps until the episode ends, under the behaviour's policy. */
function blankDemon(demons: Demon[]): DemonSpec {
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

function freeName(demons: Demon[]): string {
  const taken = new Set(demons.map((d) => d.name));
  for (let i = 1; ; i++) if (!taken.has(`demon${i}`)) return `demon${i}`;
}
