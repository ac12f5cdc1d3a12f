/**
 * The form of the Studies tab that defines and launches a study: a scenario, axes (a field path and its
 * values each, as in a study file), runs per configuration, episodes per run and checkpoints. The server
 * checks it (POST /api/studies); its 422 problems appear at the axis or field they name.
 */
import { html } from "lit-html";
import { createRef } from "lit-html/directives/ref.js";
import type { App, AppState } from "../app/app";
import { mount } from "../app/view";
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import { type StudyIn, parseValues } from "../lib/study";
import {
  FormErrors,
  bound,
  generalError,
  nothingToChoose,
  numberField,
  selectField,
  textField,
  valueOf,
} from "../ui/form";
import { choices, host } from "../ui/html";
import type { Scope } from "../ui/scope";

const DEFAULT_SCENARIO = "classroom-offpolicy";
const SUGGESTED_PATHS = [
  "learning.alpha",
  "learning.alpha_w",
  "learning.lambda",
  "demons.*.learner",
  "demons.*.alpha",
  "demons.*.lambda",
  "features.tiles",
  "world.slip",
  "seed",
];

/** The form as typed: the scenario chosen, the numbers, the axes. */
interface StudyText {
  scenario: ReturnType<typeof createRef<HTMLSelectElement>>;
  scenarioChosen: boolean;
  numbers: Record<"runs" | "episodes" | "checkpoints", string>;
  axes: Record<"path" | "values", string>[];
  launching: boolean;
}

/** The form; `onStarted` receives the id of each study it launches. */
export function studyForm(app: App, scope: Scope, onStarted: (id: string) => Promise<void>): HTMLElement {
  const element = host(html`<form class="study-form" novalidate aria-labelledby="studies-title"></form>`);
  const redraw = () => draw();
  const errors = new FormErrors(element, redraw);
  const text: StudyText = {
    scenario: createRef(),
    scenarioChosen: false,
    numbers: { runs: "3", episodes: "300", checkpoints: "10" },
    axes: [
      { path: "learning.alpha", values: "0.03, 0.1, 0.3" },
      { path: "demons.*.learner", values: "td, gq" },
    ],
    launching: false,
  };
  element.addEventListener("input", errors.onInput);
  element.addEventListener("submit", (event) => {
    event.preventDefault();
    void launch(text, errors, redraw, onStarted);
  });
  const draw = mount(app, scope, element, ["scenarios", "catalogLoaded"], (now) =>
    formTemplate(text, errors, now, redraw),
  );
  return element;
}

function formTemplate(text: StudyText, errors: FormErrors, now: AppState, redraw: () => void) {
  const names = now.scenarios.filter((x) => !x.error).map((x) => x.name);
  const chosen = text.scenarioChosen ? valueOf(text.scenario) : DEFAULT_SCENARIO;
  const number = (label: string, key: "runs" | "episodes" | "checkpoints", path: string) =>
    numberField({ label, path, errors }, { name: key, ...bound(text.numbers, key) });
  return html`<div class="row">
      ${selectField(
        { label: "Scenario", path: "scenario", errors, class: "wide" },
        { name: "scenario", ref: text.scenario, onChange: () => (text.scenarioChosen = true) },
        names.length > 0 ? choices(names, chosen) : nothingToChoose(now.catalogLoaded, "scenarios"),
      )}
      ${number("Runs per configuration", "runs", "runs")} ${number("Episodes per run", "episodes", "measure.episodes")}
      ${number("Checkpoints", "checkpoints", "measure.checkpoints")}
    </div>
    <datalist id="study-paths">${SUGGESTED_PATHS.map((p) => html`<option value=${p}></option>`)}</datalist>
    <div class="study-axes">${text.axes.map((axis, i) => axisRow(text, axis, i, errors, redraw))}</div>
    <div class="row">
      <button
        type="button"
        @click=${() => {
          text.axes = [...text.axes, { path: "", values: "" }];
          redraw();
        }}
      >
        Add an axis
      </button>
      <div class="submit-cell">
        <button type="submit" class="primary needs-change" ?disabled=${text.launching || names.length === 0}>
          Launch
        </button>
      </div>
    </div>
    ${generalError(errors)}`;
}

function axisRow(
  text: StudyText,
  axis: Record<"path" | "values", string>,
  i: number,
  errors: FormErrors,
  redraw: () => void,
) {
  const remove = () => {
    text.axes = text.axes.filter((a) => a !== axis);
    redraw();
  };
  return html`<div class="row study-axis">
    ${textField(
      { label: `Axis ${i + 1}: field path`, path: `axes.${i}.path`, errors, class: "wide" },
      { name: `axis-path-${i}`, list: "study-paths", placeholder: "learning.alpha", ...bound(axis, "path") },
    )}
    ${textField(
      { label: "Values (comma-separated)", path: `axes.${i}.values`, errors, class: "wide" },
      { name: `axis-values-${i}`, placeholder: "0.01, 0.03, 0.1", ...bound(axis, "values") },
    )}
    <button type="button" class="ghost" aria-label="Remove axis ${i + 1}" @click=${remove}>Remove</button>
  </div>`;
}

async function launch(text: StudyText, errors: FormErrors, draw: () => void, onStarted: (id: string) => Promise<void>) {
  errors.clear();
  // fields left out take the server's defaults (the generated type lists defaults as required)
  const body = {
    scenario: valueOf(text.scenario),
    runs: Number(text.numbers.runs),
    measure: { episodes: Number(text.numbers.episodes), checkpoints: Number(text.numbers.checkpoints) },
    axes: text.axes.map((a) => ({ path: a.path.trim(), values: parseValues(a.values) })),
  } as StudyIn;
  text.launching = true;
  draw();
  try {
    const started = await unwrap(api.POST("/api/studies", { body }));
    await onStarted(started.id);
  } catch (error) {
    if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
    else errors.showGeneral(errorMessage(error));
  } finally {
    text.launching = false;
    draw();
  }
}
