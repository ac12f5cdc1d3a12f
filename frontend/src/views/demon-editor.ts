/**
 * The demon editor: a question (target policy, cumulant, outcome, continuation, discount) and its
 * answer (features, learner, lambda, step sizes), added to the selected run while it runs
 * (POST /api/runs/{id}/demons). Lists of sensors, regions and demons come from the run's world.
 */
import { html } from "lit-html";
import { addDemon, notify } from "../app/actions";
import { type App, type AppState, state, watchState } from "../app/app";
import { mount } from "../app/view";
import { ApiError, errorMessage } from "../api/client";
import type { DemonSpec } from "../api/types";
import { runLabel } from "../lib/format";
import { STEP_SIZE_TEXT, choices as choicesOf, learnerChoices, noTracesWhy } from "../lib/learners";
import { regionNames, sensorNames } from "../lib/world";
import { FormErrors, bound, generalError, numberField, selectField, textField } from "../ui/form";
import { choices, host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { BLANK, BLANK_MODE, type DemonText, blankDemon, demonText, freeName, readDemon } from "./demon-form";
import { type ExprContext, exprInput, fitContext } from "./expr-input";
import { featuresFields } from "./features-fields";
import { policyFields } from "./policy-fields";

/** Step-size modes, and the run's default (README "Learners and step sizes"). */
const STEP_SIZES = [[BLANK_MODE, "the run's default"] as const, ...choicesOf(STEP_SIZE_TEXT)];
const RESETS: readonly (readonly [string, string])[] = [
  ["never", "never"],
  ["episode", "at every episode start"],
];

/** The editor's form: the demon as typed, the demon to copy, and whether the user has edited it. */
interface Editor {
  text: DemonText;
  template: string;
  touched: boolean;
  busy: boolean;
}

export function demonEditor(app: App, scope: Scope): HTMLElement {
  const element = host(html`<form class="demon-form" novalidate aria-label="Demon"></form>`);
  const redraw = () => draw();
  const errors = new FormErrors(element, redraw);
  const editor: Editor = { text: demonText(blankDemon([])), template: BLANK, touched: false, busy: false };
  const onSubmit = (event: Event) => {
    event.preventDefault();
    void submit(app, editor, errors, redraw);
  };
  const onInput = (event: Event) => {
    editor.touched = true;
    errors.onInput(event);
  };
  const draw = mount(app, scope, element, ["run", "demons", "learners"], (now) =>
    editorTemplate(editor, now, errors, redraw),
  );
  element.addEventListener("submit", onSubmit);
  element.addEventListener("input", onInput);
  element.addEventListener("change", errors.onInput);
  // The lists follow the selected run: its world's sensors and regions, its demons. Until the user
  // edits, the form offers a blank demon that fits the run (it follows its control demon).
  const follow = ({ demons }: AppState) => {
    if (!editor.touched) {
      editor.text = demonText(blankDemon(demons));
      editor.template = BLANK;
    } else if (!editor.text.name) editor.text.name = freeName(demons);
    for (const expr of [editor.text.cumulant, editor.text.outcome, editor.text.continuation]) {
      fitContext(expr, contextOf(state(app)));
    }
    draw();
  };
  watchState(app, scope, ["run", "demons"], follow);
  follow(state(app));
  return element;
}

function contextOf({ run, demons }: AppState): ExprContext {
  const world = run?.spec.world ?? {};
  // The agent is never inside an obstacle: "1 in region" offers the regions it can enter.
  const regions = regionNames(world, ["terminal", "zone", "indicator"]);
  return { sensors: sensorNames(world), regions, demons: demons.map((d) => d.name) };
}

function editorTemplate(editor: Editor, now: AppState, errors: FormErrors, redraw: () => void) {
  const { run, demons } = now;
  // Demons join created, running or paused runs; the server refuses finished and failed ones (409).
  const closed = run !== null && (run.status === "finished" || run.status === "failed");
  const note =
    run === null
      ? "Select a run in the list (or launch one) to add demons to it."
      : closed
        ? `Run ${runLabel(run)} has ${run.status}: reset it, or pick another run, to add demons.`
        : `Adds the demon to run ${runLabel(run)} (${run.status}); it learns from the next step on.`;
  const copy = () => {
    editor.touched = true;
    const source = demons.find((d) => d.name === editor.template);
    // A demon's spec comes back in the output form of the same model, which the form reads as input.
    const spec = source ? { ...(source.spec as DemonSpec), name: `${source.name}_copy` } : blankDemon(demons);
    errors.clear();
    editor.text = demonText(spec, editor.text);
    redraw();
  };
  return html`<p class="run-note" aria-live="polite">${note}</p>
    <div class="row load-row">
      ${selectField(
        { label: "Start from", id: "demon-template" },
        { onChange: (e) => (editor.template = (e.target as HTMLSelectElement).value) },
        choices(
          [[BLANK, "a blank demon"], ...demons.map((d) => [d.name, `a copy of ${d.name}`] as const)],
          editor.template,
        ),
      )}
      <button type="button" @click=${copy}>Copy into the form</button>
    </div>
    ${textField({ label: "Name", path: "name", errors, term: "demon" }, { name: "name", ...bound(editor.text, "name") })}
    <div class="editor-columns">
      ${questionFields(editor.text, now, errors, redraw)} ${answerFields(editor.text, now, errors, redraw)}
    </div>
    ${generalError(errors)}
    <div class="actions">
      <button type="submit" class="primary needs-owner" ?disabled=${run === null || closed || editor.busy}>
        Add to run
      </button>
    </div>`;
}

function questionFields(text: DemonText, now: AppState, errors: FormErrors, redraw: () => void) {
  const context = contextOf(now);
  return html`<fieldset>
    <legend>Question: what to predict</legend>
    ${policyFields(text.policy, context.demons, errors, redraw)}
    ${exprInput("Cumulant", "cumulant", text.cumulant, context, errors, redraw)}
    ${exprInput("Outcome", "outcome", text.outcome, context, errors, redraw)}
    ${exprInput("Continuation", "continuation", text.continuation, context, errors, redraw)}
    ${numberField(
      { label: "Discount", path: "discount", errors, hint: "multiplies the continuation", term: "continuation" },
      { name: "discount", ...bound(text, "discount") },
    )}
  </fieldset>`;
}

function answerFields(text: DemonText, now: AppState, errors: FormErrors, redraw: () => void) {
  const { run } = now;
  const learning = run?.spec.learning;
  // Empty fields take the run's values, shown greyed.
  const number = (
    label: string,
    key: "lambda" | "alpha" | "alpha_w" | "meta_step",
    more: object,
    placeholder?: unknown,
  ) =>
    numberField(
      { label, path: key, errors, ...more },
      { name: key, placeholder: placeholder == null ? "" : String(placeholder), ...bound(text, key) },
    );
  // A learner without traces (gtd1) learns with λ 0 whatever is typed: the field says so instead.
  const noTraces = noTracesWhy(now.learners, text.learner);
  const lambda =
    noTraces === null
      ? number("λ (lambda)", "lambda", { term: "lambda" }, learning?.lambda)
      : numberField(
          { label: "λ (lambda)", path: "lambda", errors, term: "lambda", hint: noTraces },
          { name: "lambda", current: "0", disabled: true },
        );
  return html`<fieldset>
    <legend>Answer: how to learn it</legend>
    ${selectField(
      { label: "Learner", path: "learner", errors, term: "learner" },
      { name: "learner", ...bound(text, "learner", redraw) },
      choices(learnerChoices(now.learners), text.learner),
    )}
    ${featuresFields(text.features, errors, redraw)}
    <div class="row">
      ${lambda} ${number("α (alpha)", "alpha", { term: "alpha" }, learning?.alpha)}
      ${number("α_w (alpha_w)", "alpha_w", { term: "alphaW" }, learning?.alpha_w)}
    </div>
    <div class="row">
      ${selectField(
        { label: "Step size", path: "step_size", errors, term: "stepSize" },
        { name: "step_size", ...bound(text, "step_size") },
        choices(STEP_SIZES, text.step_size),
      )}
      ${number("Meta step", "meta_step", { hint: "autostep's μ, tidbd's θ" }, learning?.meta_step)}
    </div>
    ${selectField(
      { label: "Forget the weights", path: "reset", errors },
      { name: "reset", ...bound(text, "reset") },
      choices(RESETS, text.reset),
    )}
    <p class="hint">
      Empty λ and step sizes take the run's (shown greyed). Step sizes are divided by the number of active features.
    </p>
  </fieldset>`;
}

async function submit(app: App, editor: Editor, errors: FormErrors, draw: () => void): Promise<void> {
  errors.clear();
  const runId = app.ui.state.selectedRunId;
  if (runId === null) return;
  const spec = errors.readOrShow(() => readDemon(editor.text));
  if (spec === null) return;
  if (noTracesWhy(state(app).learners, spec.learner ?? "") !== null) delete spec.lambda; // what was typed before
  editor.busy = true;
  draw();
  try {
    const demon = await addDemon(app, runId, spec);
    notify(app, `Added demon '${demon.name}' to the run.`);
    editor.text.name = freeName(state(app).demons); // the rest stays, for a variant of the same question
  } catch (error) {
    if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
    else errors.showGeneral(errorMessage(error));
  } finally {
    editor.busy = false;
    draw(); // enables the button again where the run still takes demons
  }
}
