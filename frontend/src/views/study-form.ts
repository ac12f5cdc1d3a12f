/**
 * The form of the Studies tab that defines and launches a study: a scenario, axes (a field path and its
 * values each, as in a study file), runs per configuration, episodes per run and checkpoints. The server
 * checks it (POST /api/studies); its 422 problems appear at the axis or field they name.
 */
import { type App, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import { type StudyIn, parseValues } from "../lib/study";
import { h, options, replaceChildren } from "../ui/dom";
import { FormErrors, field, nothingToChoose, numberInput, textInput } from "../ui/legacy-form";

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

interface AxisRow {
  path: HTMLInputElement;
  values: HTMLInputElement;
  row: HTMLElement;
}

/** The form; `onStarted` receives the id of each study it launches. */
export function studyForm(app: App, scope: Scope, onStarted: (id: string) => Promise<void>): HTMLElement {
  const errors = new FormErrors();
  const scenario = h("select", { name: "scenario" });
  const runs = numberInput(3, { name: "runs", min: 1 });
  const episodes = numberInput(300, { name: "episodes", min: 1 });
  const checkpoints = numberInput(10, { name: "checkpoints", min: 1 });
  const submit = h("button", { type: "submit", class: "primary" }, "Launch");
  const datalist = h(
    "datalist",
    { id: "study-paths" },
    SUGGESTED_PATHS.map((p) => h("option", { value: p })),
  );
  const axesBox = h("div", { class: "study-axes" });
  const axisRows: AxisRow[] = [];

  const addAxis = (path = "", values = "") => {
    const i = axisRows.length;
    const pathInput = textInput(path, { name: `axis-path-${i}`, list: "study-paths", placeholder: "learning.alpha" });
    const valuesInput = textInput(values, { name: `axis-values-${i}`, placeholder: "0.01, 0.03, 0.1" });
    const remove = h("button", { type: "button", class: "ghost", "aria-label": `Remove axis ${i + 1}` }, "Remove");
    const row = h(
      "div",
      { class: "row study-axis" },
      field(`Axis ${i + 1}: field path`, pathInput, { path: `axes.${i}.path`, errors, class: "wide" }),
      field("Values (comma-separated)", valuesInput, { path: `axes.${i}.values`, errors, class: "wide" }),
      remove,
    );
    const entry = { path: pathInput, values: valuesInput, row };
    remove.addEventListener("click", () => {
      axisRows.splice(axisRows.indexOf(entry), 1);
      row.remove();
    });
    axisRows.push(entry);
    axesBox.append(row);
  };
  addAxis("learning.alpha", "0.03, 0.1, 0.3");
  addAxis("demons.*.learner", "td, gq");
  const addButton = h("button", { type: "button", onclick: () => addAxis() }, "Add an axis");

  let launching = false;
  const allowLaunch = () => (submit.disabled = launching || !scenario.value);
  const renderChoices = () => {
    const names = state(app)
      .scenarios.filter((x) => !x.error)
      .map((x) => x.name);
    const chosen = scenario.dataset.chosen ? scenario.value : DEFAULT_SCENARIO;
    replaceChildren(
      scenario,
      names.length > 0 ? options(names, chosen) : nothingToChoose(state(app).catalogLoaded, "scenarios"),
    );
    allowLaunch();
  };
  scenario.addEventListener("change", () => (scenario.dataset.chosen = "yes"));

  const onSubmit = async (event: Event) => {
    event.preventDefault();
    errors.clear();
    // fields left out take the server's defaults (the generated type lists defaults as required)
    const body = {
      scenario: scenario.value,
      runs: Number(runs.value),
      measure: { episodes: Number(episodes.value), checkpoints: Number(checkpoints.value) },
      axes: axisRows.map((a) => ({ path: a.path.value.trim(), values: parseValues(a.values.value) })),
    } as StudyIn;
    launching = true;
    allowLaunch();
    try {
      const started = await unwrap(api.POST("/api/studies", { body }));
      await onStarted(started.id);
    } catch (error) {
      if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
      else errors.showGeneral(errorMessage(error));
    } finally {
      launching = false;
      allowLaunch();
    }
  };

  watchState(app, scope, ["scenarios", "catalogLoaded"], renderChoices);
  renderChoices();

  return h(
    "form",
    { class: "study-form", novalidate: true, onsubmit: onSubmit, "aria-labelledby": "studies-title" },
    h(
      "div",
      { class: "row" },
      field("Scenario", scenario, { path: "scenario", errors, class: "wide" }),
      field("Runs per configuration", runs, { path: "runs", errors }),
      field("Episodes per run", episodes, { path: "measure.episodes", errors }),
      field("Checkpoints", checkpoints, { path: "measure.checkpoints", errors }),
    ),
    datalist,
    axesBox,
    h("div", { class: "row" }, addButton, h("div", { class: "submit-cell" }, submit)),
    errors.general,
  );
}
