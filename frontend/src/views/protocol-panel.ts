/**
 * The Protocol tab: a scenario's whole protocol run in the background, as `horde run` runs it
 * (POST /api/protocols). The trials, episodes and seed start as the scenario's own; while the job
 * runs, a progress bar with the elapsed time and a Cancel button; then `horde run`'s table (each
 * demon's prediction at the start, the Monte-Carlo truth ± its standard error, the error and the
 * thesis's number) and, for control protocols, where the greedy test runs ended beside the thesis's
 * counts. A 422 appears at its field; a 429 (one protocol at a time) says so and shows the job that runs.
 * A group (all of Experiment 2) runs its scenarios one after another from this page; below, a sortable
 * table keeps the results of every job the server holds beside the thesis's numbers.
 */
import { html, nothing } from "lit-html";
import { createRef } from "lit-html/directives/ref.js";
import { attempt, cancelProtocol, loadProtocols, startProtocol } from "../app/actions";
import { type App, type AppState, state, watchState } from "../app/app";
import { mount } from "../app/view";
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import type { RunTemplate } from "../api/types";
import { protocolProgress, protocolTitle } from "../lib/protocol";
import { scenarioGroups } from "../lib/protocol-jobs";
import { readOptionalNumber } from "../lib/parse";
import { FormErrors, generalError, nothingToChoose, numberField, selectField, setValue, valueOf } from "../ui/form";
import { choices, heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { jobsTable } from "./protocol-jobs";
import { resultsTables } from "./protocol-results";

const DEFAULT_SCENARIO = "experiment1";
const GROUP = "group:";
const BUSY_MESSAGE = "One protocol at a time: another one is running already (shown below). Wait for it, or cancel it.";

/** The form's inputs, what it says of the scenario, and the group it runs. */
class ProtocolForm {
  readonly scenario = createRef<HTMLSelectElement>();
  readonly trials = createRef<HTMLInputElement>();
  readonly episodes = createRef<HTMLInputElement>();
  readonly seed = createRef<HTMLInputElement>();
  scenarioChosen = false;
  /** the choice whose numbers fill the fields, and what is said of it */
  described: string | null = null;
  description = "";
  /** the scenarios of a group still to start, the job of the group that runs now, and how many in all */
  queue: string[] = [];
  groupJob: string | null = null;
  groupSize = 0;
  /** the id of the job whose Cancel was pressed */
  cancelling: string | null = null;
  submitting = false;
}

export function protocolPanel(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel protocol-panel" aria-labelledby="protocol-title"></section>`);
  const form = new ProtocolForm();
  const redraw = () => draw();
  const errors = new FormErrors(element, redraw);
  const jobs = jobsTable(app, scope);
  const onSubmit = (event: Event) => {
    event.preventDefault();
    void submit(app, form, errors, redraw);
  };
  const onScenario = () => {
    form.scenarioChosen = true;
    void describe(app, form, redraw);
  };
  const draw = mount(
    app,
    scope,
    element,
    ["protocol", "protocolStartedAt", "scenarios", "catalogLoaded"],
    (now) =>
      html`${heading({ id: "protocol-title", title: "Protocol" })}
        <p class="hint intro">
          A scenario's whole protocol, as <code>horde run</code> runs it: every trial learns from scratch for its
          episodes; then each demon's prediction at the start is set against its Monte-Carlo truth and the thesis's
          number. It runs on the server, one at a time.
        </p>
        <form
          class="protocol-form"
          novalidate
          aria-labelledby="protocol-title"
          @submit=${onSubmit}
          @input=${errors.onInput}
          @change=${errors.onInput}
        >
          ${formFields(form, errors, now, onScenario)}
          <p class="hint scenario-description" aria-live="polite">${form.description}</p>
          <p class="hint group-note" aria-live="polite" ?hidden=${form.groupSize === 0}>${groupNote(form)}</p>
          ${generalError(errors)}
        </form>
        ${jobSection(app, form, now, redraw)} ${jobs}`,
  );
  // Once the list is drawn (and whenever it changes), the chosen scenario fills the fields.
  watchState(app, scope, ["scenarios", "catalogLoaded"], () => void describe(app, form, redraw));
  // The group's job has ended (finished, failed or cancelled): the next one starts.
  watchState(app, scope, ["protocol"], ({ protocol }) => {
    if (form.groupJob === null || protocol?.id !== form.groupJob || protocol.status === "running") return;
    if (protocol.status === "cancelled") form.queue = [];
    form.groupJob = null;
    void startNext(app, form, redraw);
  });
  return element;
}

function formFields(form: ProtocolForm, errors: FormErrors, now: AppState, onScenario: () => void) {
  const names = now.scenarios.filter((s) => !s.error).map((s) => s.name);
  const chosen = form.scenarioChosen ? valueOf(form.scenario) : DEFAULT_SCENARIO;
  const groups = scenarioGroups(names);
  const options =
    names.length === 0
      ? nothingToChoose(now.catalogLoaded, "scenarios")
      : html`<optgroup label="One scenario">${choices(names, chosen)}</optgroup>
          ${
            groups.length
              ? html`<optgroup label="A group">
                  ${choices(
                    groups.map((g) => [`${GROUP}${g.key}`, g.label] as const),
                    chosen,
                  )}
                </optgroup>`
              : nothing
          }`;
  const running = now.protocol?.status === "running";
  return html`<div class="row protocol-fields">
    ${selectField(
      { label: "Scenario", path: "scenario", errors, class: "wide" },
      { name: "scenario", ref: form.scenario, onChange: onScenario },
      options,
    )}
    ${numberField({ label: "Trials", path: "protocol.trials", errors, term: "protocol" }, { name: "trials", ref: form.trials })}
    ${numberField(
      { label: "Episodes per trial", path: "protocol.episodes", errors, class: "episodes-field" },
      { name: "episodes", ref: form.episodes },
    )}
    ${numberField({ label: "Seed", path: "seed", errors }, { name: "seed", ref: form.seed })}
    <div class="submit-cell">
      <button type="submit" class="primary needs-change" ?disabled=${running || form.submitting || names.length === 0}>
        ${running ? "Running…" : "Run"}
      </button>
    </div>
  </div>`;
}

/** The scenarios the choice stands for: one, or a group's. */
function chosenScenarios(app: App, form: ProtocolForm): string[] {
  const value = valueOf(form.scenario);
  if (!value.startsWith(GROUP)) return [value];
  const names = state(app)
    .scenarios.filter((s) => !s.error)
    .map((s) => s.name);
  return scenarioGroups(names).find((g) => `${GROUP}${g.key}` === value)?.scenarios ?? [];
}

/**
 * The scenario's own protocol and seed fill the fields, once per choice (a refreshed list keeps what the
 * user typed); a group's members each keep their own unless the user types some.
 */
async function describe(app: App, form: ProtocolForm, draw: () => void): Promise<void> {
  const members = chosenScenarios(app, form);
  const name = members[0] ?? "";
  form.description =
    members.length > 1
      ? `Runs ${members.join(", ")} one after another, each with its own protocol (the fields below apply to each; empty keeps each scenario's own). Keep this page open until the last one has started.`
      : (state(app).scenarios.find((s) => s.name === name)?.description ?? "");
  draw();
  if (members.length > 1) {
    for (const field of [form.trials, form.episodes, form.seed]) setValue(field, "");
    form.described = valueOf(form.scenario);
    return;
  }
  if (!name || name === form.described) return;
  form.described = name;
  await attempt(app, async () => {
    const spec = await unwrap(api.GET("/api/scenarios/{name}", { params: { path: { name } } }));
    if (valueOf(form.scenario) !== name) return;
    setValue(form.trials, String(spec.protocol?.trials ?? ""));
    setValue(form.episodes, String(spec.protocol?.episodes ?? ""));
    setValue(form.seed, String(spec.seed ?? ""));
  });
}

/** The request for one scenario: fields left empty keep its own values (the server checks the rest). */
function templateFor(form: ProtocolForm, name: string): RunTemplate {
  const template: RunTemplate = { scenario: name };
  const seed = readOptionalNumber(valueOf(form.seed));
  if (seed !== undefined) template.seed = seed;
  const protocol: Record<string, number> = {};
  const trials = readOptionalNumber(valueOf(form.trials));
  const episodes = readOptionalNumber(valueOf(form.episodes));
  if (trials !== undefined) protocol.trials = trials;
  if (episodes !== undefined) protocol.episodes = episodes;
  if (Object.keys(protocol).length > 0) template.protocol = protocol;
  return template;
}

async function submit(app: App, form: ProtocolForm, errors: FormErrors, draw: () => void): Promise<void> {
  errors.clear();
  const members = chosenScenarios(app, form);
  form.submitting = true;
  draw();
  try {
    const job = await startProtocol(app, templateFor(form, members[0] ?? ""));
    if (members.length > 1) {
      form.queue = members.slice(1);
      form.groupJob = job.id;
      form.groupSize = members.length;
    }
  } catch (error) {
    if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
    else if (error instanceof ApiError && error.status === 429) {
      errors.showGeneral(BUSY_MESSAGE);
      await attempt(app, () => loadProtocols(app));
    } else errors.showGeneral(errorMessage(error));
  } finally {
    form.submitting = false;
    draw();
  }
}

async function startNext(app: App, form: ProtocolForm, draw: () => void): Promise<void> {
  const name = form.queue.shift();
  if (name !== undefined) {
    const job = await attempt(app, () => startProtocol(app, templateFor(form, name)));
    form.groupJob = job?.id ?? null;
    if (form.groupJob === null) form.queue = []; // refused: the group stops here, the notice says why
  }
  draw();
}

function groupNote(form: ProtocolForm): string {
  const done = form.groupSize - form.queue.length - (form.groupJob ? 1 : 0);
  return form.groupJob || form.queue.length
    ? `Group: ${done} of ${form.groupSize} done; ${form.queue.length} waiting.`
    : `Group: all ${form.groupSize} done; their results are in the table below.`;
}

/** The job shown: its title and status, its progress and elapsed time, Cancel, then its results. */
function jobSection(app: App, form: ProtocolForm, now: AppState, draw: () => void) {
  // One section for every job (hidden while none is shown), so that it stays the same element.
  const { protocol, protocolStartedAt } = now;
  const status = protocol?.status;
  const running = status === "running";
  const elapsed = running && protocolStartedAt !== null ? Math.max(0, (Date.now() - protocolStartedAt) / 1000) : null;
  const shown = protocol ? protocolProgress(protocol, elapsed) : { fraction: 0, counted: "", timing: "" };
  const total = Math.max(1, protocol?.episodes_total ?? 1);
  const cancelling = protocol !== null && form.cancelling === protocol.id;
  const cancel = () => {
    if (protocol === null) return;
    form.cancelling = protocol.id;
    draw();
    void attempt(app, () => cancelProtocol(app));
  };
  return html`<section class="protocol-job" aria-labelledby="protocol-job-title" ?hidden=${protocol === null}>
    <div class="panel-head">
      <div class="job-title">
        <h3 id="protocol-job-title">${protocol ? protocolTitle(protocol) : ""}</h3>
        <span class="badge status-${status}">${status ?? ""}</span>
      </div>
      <button type="button" class="danger needs-teacher" ?hidden=${!running} ?disabled=${cancelling} @click=${cancel}>
        ${cancelling ? "Cancelling…" : "Cancel"}
      </button>
    </div>
    <progress
      class="protocol-progress"
      aria-labelledby="protocol-job-title"
      max=${total}
      .value=${shown.fraction * total}
      aria-valuetext=${shown.counted}
    ></progress>
    <p class="progress-text">
      <span class="progress-count" data-testid="protocol-count">${shown.counted}</span
      ><span class="progress-timing" data-testid="protocol-timing">${shown.timing ? ` · ${shown.timing}` : ""}</span>
    </p>
    <p class="form-error" role="alert" ?hidden=${status !== "failed"}>
      ${status === "failed" ? `The protocol failed: ${protocol?.error}` : ""}
    </p>
    <div class="protocol-results">${protocol?.results ? resultsTables(protocol) : nothing}</div>
  </section>`;
}
