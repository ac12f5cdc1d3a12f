/**
 * The scenario launcher: a scenario (or none), a world (the scenario's or one from the library), the
 * seed and a few overrides (episodes, speed), then POST /api/runs with the template form.
 */
import { attempt, launchRun, notify } from "../app/actions";
import type { AppStore } from "../app/state";
import { ApiError, api, unwrap } from "../api/client";
import type { RunTemplate } from "../api/types";
import { runLabel } from "../lib/format";
import { readNumber, readOptionalNumber } from "../lib/parse";
import { h, options, replaceChildren } from "../ui/dom";
import { FormErrors, checkbox, field, numberInput } from "../ui/form";

const NO_SCENARIO = "";
const SCENARIO_WORLD = "";
const DEFAULT_HZ = 20;

export function launcher(store: AppStore): HTMLElement {
  const errors = new FormErrors();
  const scenario = h("select", { name: "scenario" });
  const description = h("p", { class: "hint scenario-description", "aria-live": "polite" });
  const world = h("select", { name: "world" });
  const seed = numberInput(0, { name: "seed" });
  const episodes = numberInput(null, { name: "episodes" });
  const hz = numberInput(DEFAULT_HZ, { name: "hz" });
  const startNow = h("input", { name: "start", checked: true });
  const submit = h("button", { type: "submit", class: "primary" }, "Launch");

  const renderChoices = () => {
    const { scenarios, worlds } = store.state;
    // Experiment 1 until the user chooses (before the catalog arrives the list holds only "none").
    const chosenScenario = store.state.scenarios.length > 0 && scenario.dataset.chosen ? scenario.value : "experiment1";
    const chosenWorld = world.value;
    replaceChildren(
      scenario,
      options(
        [[NO_SCENARIO, "none: an empty run"], ...scenarios.filter((s) => !s.error).map((s) => s.name)],
        chosenScenario,
      ),
    );
    replaceChildren(
      world,
      options(
        [[SCENARIO_WORLD, "the scenario's world"], ...worlds.map((w) => [w.name, `library: ${w.name}`] as const)],
        chosenWorld,
      ),
    );
    describe();
  };

  // The scenario's own seed and episode count are shown as the values to change (once per choice,
  // so that a refreshed list does not undo what the user typed).
  let described: string | null = null;
  const describe = () => {
    const name = scenario.value;
    const entry = store.state.scenarios.find((s) => s.name === name);
    description.textContent = entry
      ? entry.description
      : "A run with the default spec: add demons with the demon editor.";
    if (!name || name === described) return;
    described = name;
    void attempt(store, async () => {
      const spec = await unwrap(api.GET("/api/scenarios/{name}", { params: { path: { name } } }));
      if (scenario.value !== name) return;
      seed.value = String(spec.seed);
      episodes.value = String(spec.protocol?.episodes ?? "");
    });
  };
  scenario.addEventListener("change", () => {
    scenario.dataset.chosen = "yes";
    describe();
  });

  const onSubmit = async (event: Event) => {
    event.preventDefault();
    errors.clear();
    const template: RunTemplate = { seed: readNumber(seed.value) };
    if (scenario.value) template.scenario = scenario.value;
    if (world.value) template.world = world.value;
    const episodeCount = readOptionalNumber(episodes.value);
    if (episodeCount !== undefined) template.protocol = { episodes: episodeCount };
    submit.disabled = true;
    try {
      const run = await launchRun(store, template, readOptionalNumber(hz.value), startNow.checked);
      notify(store, `Launched run ${runLabel(run)}.`);
      store.update({ tab: "live" });
    } catch (error) {
      if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
      else errors.showGeneral(error instanceof Error ? error.message : String(error));
    } finally {
      submit.disabled = false;
    }
  };

  store.subscribe(renderChoices, ["scenarios", "worlds"]);
  renderChoices();

  return h(
    "section",
    { class: "panel launcher", "aria-labelledby": "launcher-title" },
    h("h2", { id: "launcher-title" }, "Launch a run"),
    h(
      "form",
      { novalidate: true, onsubmit: onSubmit, "aria-labelledby": "launcher-title" },
      field("Scenario", scenario, { path: "scenario", errors }),
      description,
      field("World", world, { path: "world", errors }),
      h(
        "div",
        { class: "row" },
        field("Seed", seed, { path: "seed", errors }),
        field("Episodes", episodes, { path: "protocol.episodes", errors }),
        field("Steps/s", hz, { path: "hz", errors, hint: "empty: full speed" }),
      ),
      checkbox("Start at once", startNow),
      errors.general,
      h("div", { class: "actions" }, submit),
    ),
  );
}
