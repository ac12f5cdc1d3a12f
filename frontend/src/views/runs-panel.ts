/**
 * The list of runs: status, owner, episode and step of each, its speed, and its commands (start or pause,
 * step, reset, delete); a filter over names, scenarios and ids, and "Delete finished". Rows are kept by
 * the run's id (lit-html's `repeat`) and updated in place, so the focus stays on a button while the list
 * refreshes.
 */
import { html } from "lit-html";
import { guard } from "lit-html/directives/guard.js";
import { repeat } from "lit-html/directives/repeat.js";
import { attempt, commandRun, deleteRun, notify, selectRun, setRunSpeed, stepRun } from "../app/actions";
import type { App, AppState } from "../app/app";
import { mount } from "../app/view";
import type { RunBrief } from "../api/types";
import { formatCount, formatHz, formatStatus, runLabel } from "../lib/format";
import { FULL_SPEED, matchesFilter, speedChoice } from "../lib/runs";
import { Confirm, confirmButton } from "../ui/confirm";
import { choices, heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";

const STEP_SIZES = ["1", "10", "100", "1000"];

/** What the rows share: the app, the "press twice" state of each Delete, the steps per Step. */
interface Rows {
  app: App;
  confirms: Map<string, Confirm>;
  confirmOf: (runId: string) => Confirm;
  stepSize: () => number;
}

export function runsPanel(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel runs-panel" aria-labelledby="runs-title"></section>`);
  let filter = "";
  let stepSize = 1;
  // Each Delete keeps its "armed" state across renders, so it is made once per run.
  const confirms = new Map<string, Confirm>();
  const confirmOf = (runId: string) => {
    let confirm = confirms.get(runId);
    if (!confirm) confirms.set(runId, (confirm = new Confirm(scope, () => draw())));
    return confirm;
  };
  const rows: Rows = { app, confirms, confirmOf, stepSize: () => stepSize };
  const deleteFinished = new Confirm(scope, () => draw());
  const draw = mount(app, scope, element, ["runs", "selectedRunId", "live"], (state) => {
    const shown = state.runs.filter((r) => matchesFilter(r, filter));
    for (const id of confirms.keys()) if (!state.runs.some((r) => r.id === id)) confirms.delete(id);
    return html`${heading({
        id: "runs-title",
        title: "Runs",
        beside: html`<label for="step-size" class="inline"
          >Steps per Step
          <select id="step-size" @change=${(e: Event) => (stepSize = Number((e.target as HTMLSelectElement).value))}>
            ${choices(STEP_SIZES, String(stepSize))}
          </select></label
        >`,
      })}
      <div class="run-filter">
        <label for="run-filter">Filter runs</label>
        <input
          type="search"
          id="run-filter"
          placeholder="name, scenario, id or status"
          autocomplete="off"
          @input=${(e: Event) => {
            filter = (e.target as HTMLInputElement).value;
            draw();
          }}
        />
        <p class="hint" aria-live="polite" ?hidden=${filter.trim() === ""}>
          ${shown.length} of ${state.runs.length} runs match
        </p>
      </div>
      <div class="actions">${deleteFinishedButton(app, deleteFinished, state.runs)}</div>
      <p class="muted" ?hidden=${state.runs.length > 0}>No runs yet: launch a scenario above.</p>
      <ul class="run-list" aria-label="Runs">
        ${repeat(
          shown,
          (run) => run.id,
          (brief) => {
            // A row is drawn again only when its run, its selection or its Delete changed (the stream
            // changes the selected run's row 30 times a second; the others stay as they are).
            const run = fresher(brief, state);
            const selected = run.id === state.selectedRunId;
            return guard([run, selected, confirmOf(run.id).armed], () => runRow(rows, run, selected));
          },
        )}
      </ul>`;
  });
  return element;
}

/** Deleting every finished (or failed) run takes two presses, as deleting one does. */
function deleteFinishedButton(app: App, confirm: Confirm, runs: readonly RunBrief[]) {
  const done = runs.filter((r) => r.status === "finished" || r.status === "failed");
  return confirmButton(confirm, {
    class: "danger small needs-teacher",
    text: (armed) => (armed ? `Really delete ${done.length}?` : `Delete finished (${done.length})`),
    disabled: done.length === 0,
    onConfirm: () =>
      void attempt(app, async () => {
        for (const run of done) await deleteRun(app, run.id);
        notify(app, `Deleted ${done.length} finished run${done.length === 1 ? "" : "s"}.`);
      }),
  });
}

/** The selected run's stream is fresher than the list's once-a-second reading. */
function fresher(brief: RunBrief, { live }: AppState): RunBrief {
  if (!live || live.run !== brief.id) return brief;
  const { status, step, episode, hz, message } = live;
  return { ...brief, status, step, episode, hz, message };
}

function runRow({ app, confirmOf, stepSize }: Rows, run: RunBrief, selected: boolean) {
  const label = runLabel(run);
  const running = run.status === "running";
  const done = run.status === "finished" || run.status === "failed";
  // The server's word when it matters: kernels being prepared, or why the run failed.
  const says = run.status === "failed" || run.message.startsWith("preparing") ? run.message : "";
  const speed = speedChoice(run.hz);
  const act = (work: () => Promise<void>) => () => void attempt(app, work);
  // Whose run it is: its commands show only to its owner and the teacher (app/access.ts).
  return html`<li class="run-item ${selected ? "selected" : ""}" data-run=${run.id} data-owner=${run.owner}>
    <div class="run-head">
      <button
        type="button"
        class="run-select"
        aria-pressed=${String(selected)}
        title="Show run ${run.id}"
        @click=${act(() => selectRun(app, run.id))}
      >
        ${label}</button
      ><span class="badge status-${run.status}">${formatStatus(run.status)}</span>
    </div>
    <span class="run-owner" data-testid="run-owner">by ${run.owner}</span>
    <span class="counters" data-testid="run-counters"
      >episode ${formatCount(run.episode)} · step ${formatCount(run.step)} · ${formatHz(run.hz)}</span
    >
    <p class="run-message" role="status" ?hidden=${says === ""}>${says}</p>
    <div class="run-speed needs-owner">
      <select
        class="speed"
        aria-label="Speed of run ${label}"
        title="Steps per second: slow enough to watch each step, or as fast as the machine can learn"
        @change=${(e: Event) => {
          const value = (e.target as HTMLSelectElement).value;
          void attempt(app, () => setRunSpeed(app, run.id, value === FULL_SPEED ? null : Number(value)));
        }}
      >
        ${choices(speed.items, speed.value)}
      </select>
      <button
        type="button"
        class="small"
        aria-label="Run ${label} at full speed"
        title="Learn as fast as the machine can (the live view then shows a sample of the steps)"
        ?disabled=${run.hz === null || run.hz === undefined}
        @click=${act(() => setRunSpeed(app, run.id, null))}
      >
        Full speed
      </button>
    </div>
    <div class="run-actions needs-owner">
      <button
        type="button"
        class=${running ? "" : "primary"}
        aria-label="${running ? "Pause" : "Start"} run ${label}"
        ?disabled=${done}
        @click=${act(() => commandRun(app, run.id, running ? "pause" : "start"))}
      >
        ${running ? "Pause" : "Start"}</button
      ><button
        type="button"
        aria-label="Step run ${label}"
        ?disabled=${running || done}
        @click=${act(() => stepRun(app, run.id, stepSize()))}
      >
        Step</button
      ><button type="button" aria-label="Reset run ${label}" @click=${act(() => commandRun(app, run.id, "reset"))}>
        Reset
      </button>
      ${confirmButton(confirmOf(run.id), {
        // Deleting takes two presses, so a stray click or key cannot throw a run away.
        text: (armed) => (armed ? "Really delete?" : "Delete"),
        label: (armed) => (armed ? `Really delete run ${label}?` : `Delete run ${label}`),
        onConfirm: () =>
          void attempt(app, async () => {
            await deleteRun(app, run.id);
            notify(app, `Deleted run ${label}.`);
          }),
      })}
    </div>
  </li>`;
}
