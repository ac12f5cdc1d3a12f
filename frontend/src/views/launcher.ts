/**
 * The scenario launcher: a name, a scenario (or none), a world (the scenario's or one from the library),
 * the seed and a few overrides (episodes, speed), then POST /api/runs with the template form. The speed
 * starts at the scenario's own speed for watching (`watch_hz`, with its note on what to watch for); from a
 * server that does not say, at full speed for a protocol too long to watch. A line says how long the run
 * takes, or at a speed too slow to finish, what one sees at it. "none" is an empty run, until paused.
 */
import { attempt, launchRun, notify } from "../app/actions";
import type { AppStore } from "../app/state";
import { ApiError, api, unwrap } from "../api/client";
import type { AnyWorldSpec, RunTemplate } from "../api/types";
import { gridWorld } from "../api/types";
import { runLabel } from "../lib/format";
import { readNumber, readOptionalNumber } from "../lib/parse";
import { WATCHABLE_SECONDS, WATCH_HZ, launchEstimate, runDuration } from "../lib/runs";
import { h, options, replaceChildren, setText } from "../ui/dom";
import { FormErrors, checkbox, field, numberInput, textInput } from "../ui/form";

const NO_SCENARIO = "";
const SCENARIO_WORLD = "";
/** A live run of a thesis scenario at full speed on the 2-core development machine (measured). */
const FULL_SPEED_HZ = 200_000;
/** A live run of a Gymnasium scenario (the environment steps in Python) at full speed there (measured: README). */
const GYM_FULL_SPEED_HZ = 1_500;
/** Truncation of a Gymnasium world without its own `max_steps`: the classic-control limits are 200 to 500. */
const GYM_MAX_STEPS = 500;

/** Steps per episode at most, and steps per second at full speed, of a scenario's world. */
function worldPace(world: AnyWorldSpec | null | undefined): { maxSteps: number; fullSpeed: number } {
  if (world && "kind" in world && world.kind === "gymnasium")
    return { maxSteps: world.max_steps ?? GYM_MAX_STEPS, fullSpeed: GYM_FULL_SPEED_HZ };
  return { maxSteps: gridWorld(world)?.max_steps ?? 100, fullSpeed: FULL_SPEED_HZ };
}

export function launcher(store: AppStore): HTMLElement {
  const errors = new FormErrors();
  const scenario = h("select", { name: "scenario" });
  const description = h("p", { class: "hint scenario-description", "aria-live": "polite" });
  const world = h("select", { name: "world" });
  const seed = numberInput(0, { name: "seed" });
  const episodes = numberInput(null, { name: "episodes" });
  const hz = numberInput(WATCH_HZ, { name: "hz" });
  const name = textInput("", { name: "name", placeholder: "the scenario's name" });
  const estimate = h("p", { class: "hint estimate", "aria-live": "polite", dataset: { testid: "estimate" } });
  let maxSteps = 100;
  let fullSpeed = FULL_SPEED_HZ;
  let hzTouched = false;
  const showEstimate = () =>
    setText(
      estimate,
      launchEstimate(readOptionalNumber(episodes.value), maxSteps, readOptionalNumber(hz.value) ?? null, fullSpeed),
    );
  hz.addEventListener("input", () => {
    hzTouched = true;
    showEstimate();
  });
  episodes.addEventListener("input", showEstimate);
  const startNow = h("input", { name: "start", checked: true });
  const submit = h("button", { type: "submit", class: "primary" }, "Launch");

  // Launch waits for the catalogue: before it the list holds only "none", and the default is Experiment 1.
  let launching = false;
  const allowLaunch = () => (submit.disabled = launching || !store.state.catalogLoaded);
  const renderChoices = () => {
    const { scenarios, worlds } = store.state;
    // Experiment 1 until the user chooses.
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
    allowLaunch();
    describe();
  };

  // The scenario's own seed and episode count are shown as the values to change (once per choice,
  // so that a refreshed list does not undo what the user typed).
  let described: string | null = null;
  const describe = () => {
    showEstimate();
    const name = scenario.value;
    const entry = store.state.scenarios.find((s) => s.name === name);
    description.textContent = entry
      ? [entry.description, entry.watch_note].filter(Boolean).join(" ")
      : store.state.catalogLoaded
        ? "An empty run on the default world (or the one chosen below), until paused: add demons with the demon editor."
        : "Loading the scenarios…";
    if (name === described) return;
    described = name;
    if (!name) {
      episodes.value = "0";
      if (!hzTouched) hz.value = String(WATCH_HZ);
      showEstimate();
      return;
    }
    void attempt(store, async () => {
      const spec = await unwrap(api.GET("/api/scenarios/{name}", { params: { path: { name } } }));
      if (scenario.value !== name) return;
      seed.value = String(spec.seed);
      episodes.value = String(spec.protocol?.episodes ?? "");
      ({ maxSteps, fullSpeed } = worldPace(spec.world));
      if (spec.world && "kind" in spec.world && spec.world.kind === "gymnasium") {
        const drawn =
          spec.world.id === "horde/Baird-v0"
            ? "the star's seven states, coloured by a demon's values"
            : "a phase plane of two sensors";
        description.textContent = `${description.textContent ?? ""} Gymnasium ${spec.world.id}: the live view draws ${drawn}.`;
      }
      // The scenario's own speed for watching; from a server that does not say, a protocol too long to
      // watch starts at full speed (the run card's speed control slows it down).
      if (!hzTouched) {
        const long = runDuration(spec.protocol?.episodes ?? 0, maxSteps, WATCH_HZ, fullSpeed) > WATCHABLE_SECONDS;
        const watchHz = entry?.watch_hz === undefined ? (long ? null : WATCH_HZ) : entry.watch_hz;
        hz.value = watchHz === null ? "" : String(watchHz);
      }
      showEstimate();
    });
  };
  scenario.addEventListener("change", () => {
    scenario.dataset.chosen = "yes";
    hzTouched = false; // a speed typed for one scenario is not the next one's: it starts at its own
    describe();
  });

  const onSubmit = async (event: Event) => {
    event.preventDefault();
    errors.clear();
    const template: RunTemplate = { seed: readNumber(seed.value) };
    // A run is named after its scenario unless the user names it.
    const runName = name.value.trim() || scenario.value;
    if (runName) template.name = runName;
    if (scenario.value) template.scenario = scenario.value;
    if (world.value) template.world = world.value;
    const episodeCount = readOptionalNumber(episodes.value);
    if (episodeCount !== undefined) template.protocol = { episodes: episodeCount };
    launching = true;
    allowLaunch();
    try {
      const run = await launchRun(store, template, readOptionalNumber(hz.value), startNow.checked);
      notify(store, `Launched run ${runLabel(run)}.`);
      store.update({ tab: "live" });
    } catch (error) {
      if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
      else errors.showGeneral(error instanceof Error ? error.message : String(error));
    } finally {
      launching = false;
      allowLaunch();
    }
  };

  store.subscribe(renderChoices, ["scenarios", "worlds", "catalogLoaded"]);
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
      field("Name", name, { path: "name", errors, hint: "to find the run in the list" }),
      field("World", world, { path: "world", errors }),
      h(
        "div",
        { class: "row" },
        field("Seed", seed, { path: "seed", errors }),
        field("Episodes", episodes, { path: "protocol.episodes", errors, term: "episode" }),
        field("Steps/s", hz, { path: "hz", errors, hint: "empty: full speed", term: "speed" }),
      ),
      estimate,
      checkbox("Start at once", startNow),
      errors.general,
      h("div", { class: "actions" }, submit),
    ),
  );
}
