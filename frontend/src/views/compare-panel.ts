/**
 * Compare and export: tick two or more runs to see their demons and prediction curves side by side, or
 * protocol jobs to see their results side by side; every run and job has its export links (history or
 * results as CSV and JSON, a run's spec as TOML, so a user can share exactly what ran).
 */
import { html, nothing } from "lit-html";
import { attempt } from "../app/actions";
import { type App, state as stateOf } from "../app/app";
import { readNow } from "../app/queries";
import { reads } from "../app/reads";
import { mount } from "../app/view";
import { api, errorMessage, unwrap } from "../api/client";
import type { History, Protocol, Run, RunState } from "../api/types";
import { formatNumber, runLabel } from "../lib/format";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { bandChart } from "./study-chart";

const MAX_POINTS = 300;

const link = (href: string, text: string) => html`<a href=${href} download class="button small">${text}</a>`;

/** Download links side by side (no space between them: each keeps its own margin). */
const links = (items: [string, string][]) =>
  html`<span class="exports">${items.map(([href, text]) => link(href, text))}</span>`;

export function runExports(runId: string) {
  return links([
    [`/api/runs/${runId}/export/history?format=csv`, "History CSV"],
    [`/api/runs/${runId}/export/history?format=json`, "History JSON"],
    [`/api/runs/${runId}/export/spec`, "Spec TOML"],
  ]);
}

/** A run as compared: what it was, its state and its demons' histories, read at the press of Compare. */
interface RunColumn {
  run: Run;
  state: RunState;
  histories: History[];
}

/** What is ticked, and the columns shown side by side (a snapshot taken at the press of Compare). */
interface Comparison {
  runs: Set<string>;
  jobs: Set<string>;
  columns: (RunColumn | Protocol)[];
  note: string;
}

export function comparePanel(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="compare-panel" aria-labelledby="compare-title"></section>`);
  const chosen: Comparison = { runs: new Set(), jobs: new Set(), columns: [], note: "" };
  const tick = (set: Set<string>, id: string) => (event: Event) =>
    (event.target as HTMLInputElement).checked ? set.add(id) : set.delete(id);
  const compare = async () => {
    if (chosen.runs.size + chosen.jobs.size < 2) chosen.note = "Tick two or more runs or protocol jobs.";
    else {
      chosen.note = "";
      try {
        const runs = await Promise.all([...chosen.runs].map((id) => readRunColumn(id)));
        chosen.columns = [...runs, ...stateOf(app).protocols.filter((j) => chosen.jobs.has(j.id))];
      } catch (error) {
        chosen.note = errorMessage(error);
      }
    }
    draw();
  };
  const draw = mount(app, scope, element, ["runs", "protocols"], ({ runs, protocols }) => {
    return html`<h3 id="compare-title">Compare and export</h3>
      <p class="hint">Tick two or more runs or protocol jobs and press Compare to see them side by side.</p>
      <h4>Runs</h4>
      <ul class="compare-list">
        ${runs.map(
          (run) =>
            html`<li data-run=${run.id}>
              <label
                ><input
                  type="checkbox"
                  .checked=${chosen.runs.has(run.id)}
                  aria-label="Compare ${runLabel(run)}"
                  @change=${tick(chosen.runs, run.id)}
                />
                ${runLabel(run)} · ${run.status}</label
              >${runExports(run.id)}
            </li>`,
        )}
      </ul>
      <h4>Protocol jobs</h4>
      <ul class="compare-list">
        ${protocols.map((job) => jobItem(job, chosen.jobs.has(job.id), tick(chosen.jobs, job.id)))}
      </ul>
      <div class="row">
        <button type="button" @click=${() => void attempt(app, () => readNow(app.client, reads.protocols()))}>
          Refresh the protocol jobs
        </button>
        <button type="button" class="primary" @click=${() => void compare()}>Compare</button>
      </div>
      <p class="hint" aria-live="polite">${chosen.note}</p>
      <div class="compare-side">${chosen.columns.map((c) => ("run" in c ? runColumn(c) : jobColumn(c)))}</div>`;
  });
  return element;
}

function jobItem(job: Protocol, checked: boolean, tick: (event: Event) => void) {
  const ready = job.results !== null && job.results !== undefined;
  return html`<li>
    <label
      ><input type="checkbox" .checked=${checked} aria-label="Compare protocol ${job.id}" @change=${tick} />
      ${job.name ?? job.id} · ${job.status} · ${job.trials} x ${job.episodes} episodes</label
    >${
      ready
        ? links([
            [`/api/protocols/${job.id}/export?format=csv`, "Results CSV"],
            [`/api/protocols/${job.id}/export?format=json`, "Results JSON"],
          ])
        : nothing
    }
  </li>`;
}

async function readRunColumn(runId: string): Promise<RunColumn> {
  const path = { run_id: runId };
  const [run, state] = await Promise.all([
    unwrap(api.GET("/api/runs/{run_id}", { params: { path } })),
    unwrap(api.GET("/api/runs/{run_id}/state", { params: { path } })) as Promise<RunState>,
  ]);
  const histories = await Promise.all(
    Object.keys(state.predictions).map((name) =>
      unwrap(
        api.GET("/api/runs/{run_id}/demons/{name}/history", {
          params: { path: { run_id: runId, name }, query: { limit: 2000 } },
        }),
      ),
    ),
  );
  return { run, state, histories };
}

function runColumn({ run, state, histories }: RunColumn) {
  const series = histories.map((hist) => {
    const stride = Math.max(1, Math.ceil(hist.step.length / MAX_POINTS));
    const keep = hist.step.map((_, i) => i).filter((i) => i % stride === 0);
    const mean = keep.map((i) => hist.prediction[i] ?? null);
    const none = mean.map(() => null);
    return { label: hist.demon, x: keep.map((i) => hist.step[i] as number), mean, low: none, high: none };
  });
  return html`<div class="compare-column" data-run=${run.id}>
    <h4>${runLabel(run)} · ${run.status} · step ${state.step}</h4>
    <table class="data-table">
      <thead>
        <tr>
          <th scope="col">demon</th>
          <th scope="col" class="num">prediction now</th>
          <th scope="col" class="num">RUPEE</th>
        </tr>
      </thead>
      <tbody>
        ${Object.keys(state.predictions).map(
          (name) =>
            html`<tr>
              <td>${name}</td>
              <td class="num">${formatNumber(state.predictions[name])}</td>
              <td class="num">${formatNumber(state.metrics?.[name]?.rupee)}</td>
            </tr>`,
        )}
      </tbody>
    </table>
    ${bandChart(series, { title: "Predictions over time", xLabel: "step", yLabel: "prediction", style: "band" })}
    ${runExports(run.id)}
  </div>`;
}

function jobColumn(job: Protocol) {
  return html`<div class="compare-column">
    <h4>protocol ${job.name ?? job.id} · seed ${job.seed} · ${job.trials} x ${job.episodes}</h4>
    <table class="data-table">
      <thead>
        <tr>
          ${["demon", "prediction", "truth", "error", "thesis"].map(
            (t, i) => html`<th scope="col" class=${i ? "num" : ""}>${t}</th>`,
          )}
        </tr>
      </thead>
      <tbody>
        ${(job.results ?? []).map(
          (r) =>
            html`<tr>
              <td>${r.name}</td>
              <td class="num">${formatNumber(r.prediction)}</td>
              <td class="num">${formatNumber(r.truth)}</td>
              <td class="num">${formatNumber(r.error)}</td>
              <td class="num">${formatNumber(r.thesis)}</td>
            </tr>`,
        )}
      </tbody>
    </table>
  </div>`;
}
