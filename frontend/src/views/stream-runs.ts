/**
 * Stream runs (a world of kind `stream`, fed by a client: GET /api/streams): listed in the sidebar under
 * the runs, and, once one is selected, its strip chart in the Live tab, the nexting paper's figure: the
 * chosen sensors over the last records, and each chosen demon's prediction made at the time beside the
 * discounted return that followed, computed afterwards from the stream
 * (GET /api/streams/{id}/history). Selecting a stream run leaves the grid run selection (a stream run has
 * no episodes, steps or commands) and shows its phase plane in the embedded live view (POST /api/view: this
 * page's view only).
 */
import { html, render } from "lit-html";
import { repeat } from "lit-html/directives/repeat.js";
import { attempt, selectRun, showInLiveView } from "../app/actions";
import { type App, state, watchState } from "../app/app";
import { keys, watchQuery } from "../app/queries";
import { reads } from "../app/reads";
import type { Demon, StreamRun } from "../api/types";
import { formatCount, formatNumber } from "../lib/format";
import { pickNames } from "../lib/stream-history";
import { heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { type Strip, drawStrip, resizeStrip, stripFigure, stripPlotOf } from "./stream-strip";

const LIST_MS = 2000;
const HISTORY_MS = 1000;
const DEMONS_MS = 1000;
const RECORDS = 1000; // the strip's window
const SHOWN = 4; // sensors and demons ticked at first
const MAX_SHOWN = 8;
const MAX_BOXES = 40; // demons offered as boxes (a Horde of thousands: the first ones)
const TABLE_ROWS = 40; // rows of the stream's demon table (a Horde of thousands: the first ones)

export interface StreamViews {
  /** the sidebar's list of stream runs */
  list: HTMLElement;
  /** the Live tab's strip chart of the selected stream run (hidden while none is) */
  strip: HTMLElement;
}

export function streamRuns(app: App, scope: Scope): StreamViews {
  const list = host(html`<section class="panel stream-runs" aria-labelledby="stream-runs-title"></section>`);
  const element = host(
    html`<section
      class="panel stream-strip"
      aria-labelledby="stream-strip-title"
      data-testid="stream-strip"
      hidden
    ></section>`,
  );
  const strip: Strip = { app, scope, selected: null, sensors: [], demons: [], plots: new Map(), draw: () => draw() };
  const runs = () => app.client.getQueryData<StreamRun[]>(keys.streams) ?? [];
  const draw = () => {
    if (scope.disposed) return;
    render(listTemplate(strip, runs()), list);
    const run = runs().find((r) => r.id === strip.selected);
    element.hidden = run === undefined;
    render(run ? stripTemplate(strip, run) : "", element);
  };
  watchQuery(app.client, { ...reads.streams(), every: LIST_MS }, draw, undefined, scope);
  const watches = watchStrip(strip);
  strip.follow = () => {
    draw();
    watches.history.update(watches.historyWatch());
    watches.demons.update(watches.demonsWatch());
  };
  // Selecting a grid run leaves the stream run.
  watchState(app, scope, ["selectedRunId"], ({ selectedRunId }) => {
    if (selectedRunId === null || strip.selected === null) return;
    strip.selected = null;
    strip.follow?.();
  });
  watchState(app, scope, ["tab"], () => strip.follow?.());
  scope.resized(element, () => resizeStrip(strip));
  draw();
  return { list, strip: element };
}

/** The strip's history and its demons' table, read every second while a stream run is shown on the Live tab. */
function watchStrip(strip: Strip) {
  const { app, scope } = strip;
  const shown = () => strip.selected !== null && state(app).tab === "live";
  const historyWatch = () => ({
    ...reads.streamHistory(strip.selected ?? "", strip.sensors, strip.demons, RECORDS),
    every: HISTORY_MS,
    enabled: shown() && strip.sensors.length > 0 && strip.demons.length > 0,
  });
  const demonsWatch = () => ({ ...reads.streamDemons(strip.selected ?? ""), every: DEMONS_MS, enabled: shown() });
  const history = watchQuery(app.client, historyWatch(), (read) => drawStrip(strip, read), undefined, scope);
  const demons = watchQuery(app.client, demonsWatch(), () => strip.draw(), undefined, scope);
  return { history, historyWatch, demons, demonsWatch };
}

/** Show stream run `id`: its strip with the first sensors and demons ticked, its phase plane in the live view. */
async function choose(strip: Strip, run: StreamRun): Promise<void> {
  const { app } = strip;
  if (app.ui.state.selectedRunId !== null) await selectRun(app, null);
  strip.selected = run.id;
  strip.sensors = pickNames(run.sensors, strip.sensors, SHOWN, MAX_SHOWN);
  strip.demons = pickNames(run.demons, strip.demons, SHOWN, MAX_SHOWN);
  app.ui.update({ tab: "live" });
  strip.follow?.();
  await showInLiveView(app, run.id);
}

function listTemplate(strip: Strip, runs: StreamRun[]) {
  const item = (run: StreamRun) => {
    const chosen = run.id === strip.selected;
    return html`<li class="run-item ${chosen ? "selected" : ""}" data-stream=${run.id}>
      <button
        type="button"
        class="link"
        aria-pressed=${String(chosen)}
        @click=${() => void attempt(strip.app, () => choose(strip, run))}
      >
        ${run.name || "stream"} · ${run.id.slice(0, 6)}</button
      ><span class="hint">
        ${formatCount(run.learned)} records learned of ${formatCount(run.received)} received · ${run.sensors.length}
        sensors · ${run.demons.length} demons</span
      >
    </li>`;
  };
  return html`${heading({ id: "stream-runs-title", title: "Stream runs" })}
    <p class="hint">
      Runs that learn from records a robot or a replayed log pushes. Select one to see its phase plane and its strip
      chart.
    </p>
    <ul class="run-list" aria-label="Stream runs">
      ${repeat(runs, (run) => run.id, item)}
    </ul>
    <p class="muted" ?hidden=${runs.length > 0}>
      No stream runs. A client starts one with POST /api/streams and pushes records to it (see the README).
    </p>`;
}

function stripTemplate(strip: Strip, run: StreamRun) {
  const keys = [...strip.sensors.map((s) => `sensor:${s}`), ...strip.demons.map((d) => `demon:${d}`)];
  for (const [key, plot] of strip.plots) {
    if (keys.includes(key)) continue;
    plot.scope.dispose();
    strip.plots.delete(key);
  }
  const more = run.demons.length > MAX_BOXES ? ` (the first ${MAX_BOXES} of ${run.demons.length})` : "";
  return html`<h2 id="stream-strip-title">
      Stream run ${run.name || run.id.slice(0, 6)}: predictions beside realised returns
    </h2>
    <p class="hint" aria-live="polite">
      ${formatCount(run.learned)} records learned of ${formatCount(run.received)} received; ${run.demons.length} demons
      over ${run.sensors.join(", ")}. Its phase plane is in the live view below.
    </p>
    <p class="hint">
      The last ${formatCount(RECORDS)} records, by their number in the stream. Green: a sensor's reading. Blue: the
      demon's prediction, made on observing the record. Dashed black: the discounted return that actually followed,
      computed afterwards from the later records (blank for the newest records, whose return is not known yet, and
      before a refused record; it is the behaviour's return, so it is the answer only for on-policy demons). No Evaluate
      here: a stream's records come from outside, so there is no copy of its world to roll a target policy out in; the
      realised return is the truth a stream has.
    </p>
    ${ticks(strip, "Sensors", run.sensors, "sensors")} ${ticks(strip, `Demons${more}`, run.demons, "demons")}
    <div class="chart-grid">
      ${repeat(
        keys,
        (key) => key,
        (key) => stripFigure(stripPlotOf(strip, key)),
      )}
    </div>
    ${demonsTable(strip)}
    <a
      class="hint"
      download="stream-snapshot.json"
      data-testid="stream-snapshot"
      href="/api/streams/${encodeURIComponent(run.id)}/snapshot"
      >Download a snapshot (POST it to /api/streams/import to go on from here)</a
    >`;
}

/** The boxes that choose which sensors (or demons) are drawn. */
function ticks(strip: Strip, legend: string, offered: readonly string[], which: "sensors" | "demons") {
  const tick = (name: string) => (event: Event) => {
    const now = strip[which].filter((n) => n !== name);
    strip[which] = (event.target as HTMLInputElement).checked ? [...now, name].slice(0, MAX_SHOWN) : now;
    strip.follow?.();
  };
  return html`<fieldset class="stream-pick">
    <legend>${legend}</legend>
    ${offered
      .slice(0, MAX_BOXES)
      .map(
        (name) =>
          html`<label class="stream-tick"
            ><input type="checkbox" .checked=${strip[which].includes(name)} @change=${tick(name)} /> ${name}</label
          >`,
      )}
  </fieldset>`;
}

function demonsTable(strip: Strip) {
  const rows = strip.app.client.getQueryData<Demon[]>(keys.streamDemons(strip.selected ?? "")) ?? [];
  return html`<table class="stream-demons" data-testid="stream-demons">
    <caption>
      Demons at the last record: prediction, RUPEE (how far it still is from its fixed point) and UDE (how surprised it
      is).
    </caption>
    <thead>
      <tr>
        <th>demon</th>
        <th>prediction</th>
        <th>RUPEE</th>
        <th>UDE</th>
      </tr>
    </thead>
    <tbody>
      ${repeat(
        rows.slice(0, TABLE_ROWS),
        (d) => d.name,
        (d) =>
          html`<tr data-demon=${d.name}>
            <td>${d.metrics.diverged ? `${d.name} (diverged)` : d.name}</td>
            <td>${formatNumber(d.prediction)}</td>
            <td>${formatNumber(d.metrics.rupee)}</td>
            <td>${formatNumber(d.metrics.ude)}</td>
          </tr>`,
      )}
    </tbody>
  </table>`;
}
