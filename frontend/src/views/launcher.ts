/**
 * The scenario launcher: a name, a scenario (or none), a world (the scenario's or one from the library),
 * the seed and a few overrides (episodes, speed), then POST /api/runs with the template form. The speed
 * starts at the scenario's own speed for watching (`watch_hz`, with its note on what to watch for); from a
 * server that does not say, at full speed for a protocol too long to watch. A line says how long the run
 * takes, or at a speed too slow to finish, what one sees at it. "none" is an empty run, until paused.
 */
import { html } from "lit-html";
import { createRef } from "lit-html/directives/ref.js";
import { attempt, launchRun, notify } from "../app/actions";
import { type App, type AppState, state, watchState } from "../app/app";
import { mount } from "../app/view";
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import type { AnyWorldSpec, RunTemplate } from "../api/types";
import { gridWorld } from "../api/types";
import { runLabel } from "../lib/format";
import { readNumber, readOptionalNumber } from "../lib/parse";
import { WATCHABLE_SECONDS, WATCH_HZ, launchEstimate, runDuration } from "../lib/runs";
import { FormErrors, checkbox, generalError, numberField, selectField, setValue, textField, valueOf } from "../ui/form";
import { choices, host } from "../ui/html";
import type { Scope } from "../ui/scope";

const NO_SCENARIO = "";
const SCENARIO_WORLD = "";
const DEFAULT_SCENARIO = "experiment1";
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

/** The form's inputs, and what it knows besides them. */
class Launcher {
  readonly scenario = createRef<HTMLSelectElement>();
  readonly world = createRef<HTMLSelectElement>();
  readonly seed = createRef<HTMLInputElement>();
  readonly episodes = createRef<HTMLInputElement>();
  readonly hz = createRef<HTMLInputElement>();
  readonly name = createRef<HTMLInputElement>();
  readonly start = createRef<HTMLInputElement>();
  maxSteps = 100;
  fullSpeed = FULL_SPEED_HZ;
  /** the user typed a speed: a scenario chosen later keeps it */
  hzTouched = false;
  /** the user chose a scenario: a refreshed list keeps it */
  scenarioChosen = false;
  launching = false;
  /** the scenario whose seed and episodes fill the fields, and what is said of it */
  described: string | null = null;
  note = "";

  estimate(): string {
    const hz = readOptionalNumber(valueOf(this.hz)) ?? null;
    return launchEstimate(readOptionalNumber(valueOf(this.episodes)), this.maxSteps, hz, this.fullSpeed);
  }
}

export function launcher(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel launcher needs-change" aria-labelledby="launcher-title"></section>`);
  const form = new Launcher();
  const redraw = () => draw();
  const errors = new FormErrors(element, redraw);
  const onSubmit = (event: Event) => {
    event.preventDefault();
    void launch(app, form, errors, redraw);
  };
  const draw = mount(
    app,
    scope,
    element,
    ["scenarios", "worlds", "catalogLoaded"],
    (now) =>
      html`<h2 id="launcher-title">Launch a run</h2>
        <form
          novalidate
          aria-labelledby="launcher-title"
          @submit=${onSubmit}
          @input=${errors.onInput}
          @change=${errors.onInput}
        >
          ${fields(
            form,
            errors,
            now,
            () => {
              form.scenarioChosen = true;
              form.hzTouched = false; // a speed typed for one scenario is not the next one's: it starts at its own
              void describe(app, form, redraw);
            },
            redraw,
          )}
          <p class="hint estimate" aria-live="polite" data-testid="estimate">${form.estimate()}</p>
          ${checkbox("Start at once", "launch-start", { name: "start", checked: true, ref: form.start })}
          ${generalError(errors)}
          <div class="actions">
            <button type="submit" class="primary" ?disabled=${form.launching || !now.catalogLoaded}>Launch</button>
          </div>
        </form>`,
  );
  // Once the list is drawn (and whenever it changes), the chosen scenario fills the fields.
  watchState(app, scope, ["scenarios", "catalogLoaded"], () => void describe(app, form, draw));
  void describe(app, form, draw);
  return element;
}

function fields(form: Launcher, errors: FormErrors, now: AppState, onScenario: () => void, draw: () => void) {
  const { scenarios, worlds } = now;
  // Experiment 1 until the user chooses.
  const chosen = scenarios.length > 0 && form.scenarioChosen ? valueOf(form.scenario) : DEFAULT_SCENARIO;
  const onHz = () => {
    form.hzTouched = true;
    draw();
  };
  return html`${selectField(
      { label: "Scenario", path: "scenario", errors },
      { name: "scenario", ref: form.scenario, onChange: onScenario },
      choices([[NO_SCENARIO, "none: an empty run"], ...scenarios.filter((s) => !s.error).map((s) => s.name)], chosen),
    )}
    <p class="hint scenario-description" aria-live="polite">${form.note}</p>
    ${textField(
      { label: "Name", path: "name", errors, hint: "to find the run in the list" },
      { name: "name", placeholder: "the scenario's name", ref: form.name },
    )}
    ${selectField(
      { label: "World", path: "world", errors },
      { name: "world", ref: form.world },
      choices(
        [[SCENARIO_WORLD, "the scenario's world"], ...worlds.map((w) => [w.name, `library: ${w.name}`] as const)],
        valueOf(form.world),
      ),
    )}
    <div class="row">
      ${numberField({ label: "Seed", path: "seed", errors }, { name: "seed", value: 0, ref: form.seed })}
      ${numberField(
        { label: "Episodes", path: "protocol.episodes", errors, term: "episode" },
        { name: "episodes", ref: form.episodes, onInput: draw },
      )}
      ${numberField(
        { label: "Steps/s", path: "hz", errors, hint: "empty: full speed", term: "speed" },
        { name: "hz", value: WATCH_HZ, ref: form.hz, onInput: onHz },
      )}
    </div>`;
}

/**
 * Say what the chosen scenario is, and fill the fields with its own seed, episodes and speed for watching
 * (once per choice, so that a refreshed list does not undo what the user typed).
 */
async function describe(app: App, form: Launcher, draw: () => void): Promise<void> {
  const name = valueOf(form.scenario);
  const { scenarios, catalogLoaded } = state(app);
  const entry = scenarios.find((s) => s.name === name);
  form.note = entry
    ? [entry.description, entry.watch_note].filter(Boolean).join(" ")
    : catalogLoaded
      ? "An empty run on the default world (or the one chosen below), until paused: add demons with the demon editor."
      : "Loading the scenarios…";
  draw();
  if (name === form.described || (!name && !catalogLoaded)) return;
  form.described = name;
  if (!name) {
    setValue(form.episodes, "0");
    if (!form.hzTouched) setValue(form.hz, String(WATCH_HZ));
    draw();
    return;
  }
  await attempt(app, async () => {
    const spec = await unwrap(api.GET("/api/scenarios/{name}", { params: { path: { name } } }));
    if (valueOf(form.scenario) !== name) return;
    setValue(form.seed, String(spec.seed));
    setValue(form.episodes, String(spec.protocol?.episodes ?? ""));
    ({ maxSteps: form.maxSteps, fullSpeed: form.fullSpeed } = worldPace(spec.world));
    if (spec.world && "kind" in spec.world && spec.world.kind === "gymnasium") {
      const drawn =
        spec.world.id === "horde/Baird-v0"
          ? "the star's seven states, coloured by a demon's values"
          : "a phase plane of two sensors";
      form.note = `${form.note} Gymnasium ${spec.world.id}: the live view draws ${drawn}.`;
    }
    // The scenario's own speed for watching; from a server that does not say, a protocol too long to
    // watch starts at full speed (the run card's speed control slows it down).
    if (!form.hzTouched) {
      const steps = runDuration(spec.protocol?.episodes ?? 0, form.maxSteps, WATCH_HZ, form.fullSpeed);
      const watchHz = entry?.watch_hz === undefined ? (steps > WATCHABLE_SECONDS ? null : WATCH_HZ) : entry.watch_hz;
      setValue(form.hz, watchHz === null ? "" : String(watchHz));
    }
    draw();
  });
}

async function launch(app: App, form: Launcher, errors: FormErrors, draw: () => void): Promise<void> {
  errors.clear();
  const template: RunTemplate = { seed: readNumber(valueOf(form.seed)) };
  const scenario = valueOf(form.scenario);
  // A run is named after its scenario unless the user names it.
  const runName = valueOf(form.name).trim() || scenario;
  if (runName) template.name = runName;
  if (scenario) template.scenario = scenario;
  if (valueOf(form.world)) template.world = valueOf(form.world);
  const episodeCount = readOptionalNumber(valueOf(form.episodes));
  if (episodeCount !== undefined) template.protocol = { episodes: episodeCount };
  form.launching = true;
  draw();
  try {
    const run = await launchRun(app, template, readOptionalNumber(valueOf(form.hz)), form.start.value?.checked ?? true);
    notify(app, `Launched run ${runLabel(run)}.`);
    app.ui.update({ tab: "live" });
  } catch (error) {
    if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
    else errors.showGeneral(errorMessage(error));
  } finally {
    form.launching = false;
    draw();
  }
}
