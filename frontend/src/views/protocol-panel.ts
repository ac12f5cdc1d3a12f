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
import { attempt, cancelProtocol, loadProtocols, startProtocol } from "../app/actions";
import { type App, type AppState, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { ApiError, api, unwrap } from "../api/client";
import type { Protocol, RunTemplate } from "../api/types";
import { countsTable, protocolProgress, protocolSummary, protocolTitle, resultRows } from "../lib/protocol";
import { tip } from "../lib/glossary";
import { jobsTable } from "./protocol-jobs";
import { scenarioGroups } from "../lib/protocol-jobs";
import { readOptionalNumber } from "../lib/parse";
import { h, options, replaceChildren, section, setText } from "../ui/dom";
import { FormErrors, field, nothingToChoose, numberInput } from "../ui/legacy-form";

const DEFAULT_SCENARIO = "experiment1";
const GROUP = "group:";
const HEAD_TIPS: Record<string, string | undefined> = {
  demon: tip("demon"),
  prediction: tip("prediction"),
  "truth (MC) ± se": tip("truth"),
  thesis: tip("thesis"),
};
const BUSY_MESSAGE = "One protocol at a time: another one is running already (shown below). Wait for it, or cancel it.";

export function protocolPanel(app: App, scope: Scope): HTMLElement {
  const errors = new FormErrors();
  const scenario = h("select", { name: "scenario" });
  const description = h("p", { class: "hint scenario-description", "aria-live": "polite" });
  const trials = numberInput(null, { name: "trials" });
  const episodes = numberInput(null, { name: "episodes" });
  const seed = numberInput(null, { name: "seed" });
  const submit = h("button", { type: "submit", class: "primary" }, "Run");

  // ---------------------------------------------------------------- the form

  const renderChoices = () => {
    const names = state(app)
      .scenarios.filter((s) => !s.error)
      .map((s) => s.name);
    const chosen = scenario.dataset.chosen ? scenario.value : DEFAULT_SCENARIO;
    const groups = scenarioGroups(names);
    if (names.length === 0) replaceChildren(scenario, nothingToChoose(state(app).catalogLoaded, "scenarios"));
    else
      replaceChildren(
        scenario,
        h("optgroup", { label: "One scenario" }, options(names, chosen)),
        groups.length
          ? h(
              "optgroup",
              { label: "A group" },
              options(
                groups.map((g) => [`${GROUP}${g.key}`, g.label] as const),
                chosen,
              ),
            )
          : null,
      );
    render(state(app));
    describe();
  };

  /** The scenarios the choice stands for: one, or a group's. */
  const chosenScenarios = (): string[] => {
    const value = scenario.value;
    if (!value.startsWith(GROUP)) return [value];
    const names = state(app)
      .scenarios.filter((s) => !s.error)
      .map((s) => s.name);
    return scenarioGroups(names).find((g) => `${GROUP}${g.key}` === value)?.scenarios ?? [];
  };

  // The scenario's own protocol and seed fill the fields, once per choice (a refreshed list keeps
  // what the user typed).
  let described: string | null = null;
  const describe = () => {
    const members = chosenScenarios();
    const name = members[0] ?? "";
    description.textContent =
      members.length > 1
        ? `Runs ${members.join(", ")} one after another, each with its own protocol (the fields below apply to each; empty keeps each scenario's own). Keep this page open until the last one has started.`
        : (state(app).scenarios.find((s) => s.name === name)?.description ?? "");
    if (members.length > 1) {
      // Each keeps its own numbers unless the user types some.
      trials.value = episodes.value = seed.value = "";
      described = scenario.value;
      return;
    }
    if (!name || name === described) return;
    described = name;
    void attempt(app, async () => {
      const spec = await unwrap(api.GET("/api/scenarios/{name}", { params: { path: { name } } }));
      if (scenario.value !== name) return;
      trials.value = String(spec.protocol?.trials ?? "");
      episodes.value = String(spec.protocol?.episodes ?? "");
      seed.value = String(spec.seed ?? "");
    });
  };
  scenario.addEventListener("change", () => {
    scenario.dataset.chosen = "yes";
    describe();
  });

  // The scenarios of a group still to start, and the job of the group that runs now.
  let queue: string[] = [];
  let groupJob: string | null = null;
  let groupSize = 0;
  const groupNote = h("p", { class: "hint group-note", "aria-live": "polite", hidden: true });

  const templateFor = (name: string): RunTemplate => {
    // Fields left empty keep the scenario's values; the server checks the rest (422 at the field).
    const template: RunTemplate = { scenario: name };
    const seedValue = readOptionalNumber(seed.value);
    if (seedValue !== undefined) template.seed = seedValue;
    const protocol: Record<string, number> = {};
    const trialCount = readOptionalNumber(trials.value);
    const episodeCount = readOptionalNumber(episodes.value);
    if (trialCount !== undefined) protocol.trials = trialCount;
    if (episodeCount !== undefined) protocol.episodes = episodeCount;
    if (Object.keys(protocol).length > 0) template.protocol = protocol;
    return template;
  };

  const startNext = async () => {
    const name = queue.shift();
    if (name === undefined) {
      groupJob = null;
      return;
    }
    const job = await attempt(app, () => startProtocol(app, templateFor(name)));
    groupJob = job?.id ?? null;
    if (groupJob === null) queue = []; // refused: the group stops here, the notice says why
    showGroup();
  };

  const showGroup = () => {
    groupNote.hidden = groupSize === 0;
    const done = groupSize - queue.length - (groupJob ? 1 : 0);
    setText(
      groupNote,
      groupJob || queue.length
        ? `Group: ${done} of ${groupSize} done; ${queue.length} waiting.`
        : `Group: all ${groupSize} done; their results are in the table below.`,
    );
  };

  // The group's job has ended (finished, failed or cancelled): the next one starts.
  watchState(app, scope, ["protocol"], ({ protocol }) => {
    if (groupJob !== null && protocol?.id === groupJob && protocol.status !== "running") {
      if (protocol.status === "cancelled") queue = [];
      groupJob = null;
      void startNext().then(showGroup);
    }
  });

  const onSubmit = async (event: Event) => {
    event.preventDefault();
    errors.clear();
    const members = chosenScenarios();
    const template = templateFor(members[0] ?? "");
    submit.disabled = true;
    try {
      const job = await startProtocol(app, template);
      if (members.length > 1) {
        queue = members.slice(1);
        groupJob = job.id;
        groupSize = members.length;
        showGroup();
      }
    } catch (error) {
      if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
      else if (error instanceof ApiError && error.status === 429) {
        errors.showGeneral(BUSY_MESSAGE);
        await attempt(app, () => loadProtocols(app));
      } else errors.showGeneral(error instanceof Error ? error.message : String(error));
    } finally {
      render(state(app));
    }
  };

  // ---------------------------------------------------------------- the job

  const title = h("h3", { id: "protocol-job-title" });
  const status = h("span", { class: "badge" });
  const cancel = h("button", { type: "button", class: "danger" }, "Cancel");
  const progress = h("progress", { class: "protocol-progress", "aria-labelledby": "protocol-job-title" });
  const counted = h("span", { class: "progress-count", dataset: { testid: "protocol-count" } });
  const timing = h("span", { class: "progress-timing", dataset: { testid: "protocol-timing" } });
  const failure = h("p", { class: "form-error", role: "alert", hidden: true });
  const results = h("div", { class: "protocol-results" });
  let cancelling: string | null = null; // the id of the job whose Cancel was pressed
  let shownResults: Protocol | null = null;

  cancel.addEventListener("click", () => {
    const job = state(app).protocol;
    if (!job) return;
    cancelling = job.id;
    render(state(app));
    void attempt(app, () => cancelProtocol(app));
  });

  const job = h(
    "section",
    { class: "protocol-job", "aria-labelledby": "protocol-job-title", hidden: true },
    h("div", { class: "panel-head" }, h("div", { class: "job-title" }, title, status), cancel),
    progress,
    h("p", { class: "progress-text" }, counted, timing),
    failure,
    results,
  );

  const render = (state: Readonly<AppState>) => {
    const { protocol, protocolStartedAt } = state;
    const running = protocol?.status === "running";
    submit.disabled = running || !scenario.value;
    setText(submit, running ? "Running…" : "Run");
    job.hidden = protocol === null;
    if (protocol === null) return;

    setText(title, protocolTitle(protocol));
    setText(status, protocol.status);
    status.className = `badge status-${protocol.status}`;
    cancel.hidden = !running;
    cancel.disabled = cancelling === protocol.id;
    setText(cancel, cancelling === protocol.id ? "Cancelling…" : "Cancel");

    const elapsed = running && protocolStartedAt !== null ? Math.max(0, (Date.now() - protocolStartedAt) / 1000) : null;
    const shown = protocolProgress(protocol, elapsed);
    progress.max = Math.max(1, protocol.episodes_total);
    progress.value = shown.fraction * progress.max;
    progress.setAttribute("aria-valuetext", shown.counted);
    setText(counted, shown.counted);
    setText(timing, shown.timing ? ` · ${shown.timing}` : "");
    failure.hidden = protocol.status !== "failed";
    setText(failure, protocol.status === "failed" ? `The protocol failed: ${protocol.error}` : "");

    // The tables are built once per answer that has results (not four times a second).
    if (shownResults?.id === protocol.id && shownResults.results === protocol.results) return;
    shownResults = protocol;
    replaceChildren(results, protocol.results ? resultsTables(protocol) : null);
  };
  watchState(app, scope, ["protocol", "protocolStartedAt"], render);
  watchState(app, scope, ["scenarios", "catalogLoaded"], renderChoices);
  renderChoices();

  return section(
    { class: "panel protocol-panel", id: "protocol-title", title: "Protocol" },
    h(
      "p",
      { class: "hint intro" },
      "A scenario's whole protocol, as ",
      h("code", {}, "horde run"),
      " runs it: every trial learns from scratch for its episodes; then each demon's prediction at the start is set " +
        "against its Monte-Carlo truth and the thesis's number. It runs on the server, one at a time.",
    ),
    h(
      "form",
      { class: "protocol-form", novalidate: true, onsubmit: onSubmit, "aria-labelledby": "protocol-title" },
      h(
        "div",
        { class: "row protocol-fields" },
        field("Scenario", scenario, { path: "scenario", errors, class: "wide" }),
        field("Trials", trials, { path: "protocol.trials", errors, term: "protocol" }),
        field("Episodes per trial", episodes, { path: "protocol.episodes", errors, class: "episodes-field" }),
        field("Seed", seed, { path: "seed", errors }),
        h("div", { class: "submit-cell" }, submit),
      ),
      description,
      groupNote,
      errors.general,
    ),
    job,
    jobsTable(app, scope),
  );
}

/** `horde run`'s table, and the test runs' counts beside the thesis's for a control protocol. */
function resultsTables(job: Protocol): HTMLElement[] {
  const rows = resultRows(job.results ?? []);
  const counts = countsTable(job.results ?? [], job.thesis_counts);
  const head = (labels: string[]) =>
    h(
      "thead",
      {},
      h(
        "tr",
        {},
        labels.map((label, i) =>
          h(
            "th",
            { scope: "col", class: i ? "num" : "", title: HEAD_TIPS[label] },
            HEAD_TIPS[label] ? h("span", { class: "term" }, label) : label,
          ),
        ),
      ),
    );
  const tables: HTMLElement[] = [
    h("h4", {}, "Predictions at the start, mean over trials"),
    h(
      "div",
      { class: "table-scroll" },
      h(
        "table",
        { class: "results-table protocol-table" },
        h(
          "caption",
          { class: "visually-hidden" },
          "Each demon's prediction against the Monte-Carlo truth and the thesis",
        ),
        head(["demon", "prediction", "truth (MC) ± se", "error", "error %", "thesis"]),
        h(
          "tbody",
          {},
          rows.map((row) =>
            h(
              "tr",
              { dataset: { demon: row.name } },
              h("th", { scope: "row" }, row.name),
              [row.prediction, row.truth, row.error, row.relative, row.thesis].map((text) =>
                h("td", { class: "num" }, text),
              ),
            ),
          ),
        ),
      ),
    ),
  ];
  if (counts) {
    tables.push(
      h("h4", {}, `Greedy test runs of ${counts.demon}: where they ended`),
      h(
        "div",
        { class: "table-scroll" },
        h(
          "table",
          { class: "counts-table" },
          h("caption", { class: "visually-hidden" }, "This protocol's test runs beside the thesis's"),
          head(["", "positive terminal", "negative terminal", "none (step limit)"]),
          h(
            "tbody",
            {},
            counts.rows.map((row) =>
              h(
                "tr",
                { dataset: { counts: row.key } },
                h("th", { scope: "row" }, row.label),
                [row.positive, row.negative, row.none].map((text) => h("td", { class: "num" }, text)),
              ),
            ),
          ),
        ),
      ),
    );
  }
  tables.push(h("p", { class: "muted protocol-summary" }, protocolSummary(job)));
  return tables;
}
