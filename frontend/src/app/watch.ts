/**
 * The data the whole page follows, for as long as its scope lives: the run list every second; the
 * selected run (its entries held in the cache while it is selected) and its WebSocket stream, which also
 * notices when demons join or leave (the run is read again) and when it finishes; the protocol job shown,
 * four readings a second while it runs (its progress, then its results); and the demons the live view
 * labels, at the page's Large text. The readings are queries of app/reads.ts, their answers the query cache's.
 */
import { ApiError } from "../api/client";
import { RunStream } from "../api/stream";
import type { Protocol, RunState } from "../api/types";
import type { Scope } from "../ui/scope";
import { VIEW_DEMONS, applyRuns, attempt, notify, protocolEnded, reloadSelectedRun, showInLiveView } from "./actions";
import { type App, chartedDemons, state, watchState } from "./app";
import { hold, keys, watchQuery } from "./queries";
import { reads } from "./reads";

const RUNS_PERIOD_MS = 1000;
const PROTOCOL_PERIOD_MS = 250;
const TELL_VIEW_MS = 300;

/** Everything below, until `scope` goes. */
export function watchApp(app: App, scope: Scope): void {
  // The catalogue, the live view's address, the protocol jobs and who the page is stay in the cache for the
  // page's life.
  for (const key of [keys.scenarios, keys.worlds, keys.view, keys.protocols, keys.me]) hold(app.client, key, scope);
  watchRuns(app, scope);
  watchSelectedRun(app, scope);
  watchProtocol(app, scope);
  watchChartedForView(app, scope);
}

export function watchRuns(app: App, scope: Scope): void {
  // A failed reading (the server may be restarting) is simply tried again at the next interval.
  const runs = { ...reads.runs(), every: RUNS_PERIOD_MS };
  watchQuery(app.client, runs, (read) => applyRuns(app, read), undefined, scope);
}

/** While a run is selected: its entries held, its stream open; both let go when another is selected. */
export function watchSelectedRun(app: App, scope: Scope): void {
  let selection: Scope | null = null;
  const follow = () => {
    selection?.dispose();
    selection = null;
    const runId = app.ui.state.selectedRunId;
    if (runId === null) return;
    const held = scope.child();
    selection = held;
    for (const key of [keys.run(runId), keys.demons(runId), keys.live(runId), keys.evaluations(runId)]) {
      hold(app.client, key, held);
    }
    // One reading of the run at a time: messages keep coming (30 a second) while it is under way.
    let reloading = false;
    const reload = () => {
      if (reloading) return;
      reloading = true;
      void attempt(app, () => reloadSelectedRun(app)).finally(() => (reloading = false));
    };
    const stream = new RunStream(
      runId,
      (message) => onMessage(app, runId, message, reload),
      (reason) => notify(app, `The stream of run ${runId.slice(0, 6)} ended: ${reason}`),
    );
    held.add(() => stream.close());
  };
  scope.add(app.ui.subscribe(follow, ["selectedRunId"]));
  follow();
}

function onMessage(app: App, runId: string, incoming: RunState, reload: () => void): void {
  const { selectedRunId, run, demons, live } = state(app);
  if (selectedRunId !== runId) return;
  const message = mergeWindow(live, incoming, demons);
  app.client.setQueryData(keys.live(runId), message);
  const total = incoming.demon_total || Object.keys(incoming.predictions).length;
  const known = demonNames(demons);
  const demonsChanged = total !== demons.length || Object.keys(incoming.predictions).some((name) => !known.has(name));
  // Compared with what was last read (not the previous message), so a change missed during a reading
  // is caught by the next message.
  const statusChanged = run !== null && run.status !== message.status;
  if (demonsChanged || statusChanged) reload();
}

// The names of the demon list last read, kept while the list is the same.
let namesOf: { demons: readonly { name: string }[]; names: Set<string> } | null = null;

function demonNames(demons: readonly { name: string }[]): Set<string> {
  if (namesOf?.demons !== demons) namesOf = { demons, names: new Set(demons.map((d) => d.name)) };
  return namesOf.names;
}

/**
 * A large Horde's stream message carries some demons only (the next ones in turn): the others keep their
 * last known values, so the table and the overview always hold every demon.
 */
export function mergeWindow(
  previous: RunState | null,
  message: RunState,
  demons: readonly { name: string }[],
): RunState {
  const total = message.demon_total || 0;
  if (total <= Object.keys(message.predictions).length || previous === null || previous.run !== message.run) {
    return message;
  }
  const predictions: RunState["predictions"] = {};
  const metrics: RunState["metrics"] = {};
  for (const { name } of demons) {
    const p = message.predictions[name] !== undefined ? message.predictions[name] : previous.predictions[name];
    if (p !== undefined) predictions[name] = p;
    const m = message.metrics[name] ?? previous.metrics[name];
    if (m !== undefined) metrics[name] = m;
  }
  return { ...message, predictions, metrics };
}

/** The live view labels the demons the dashboard charts, at its Large text: told again when either changes. */
export function watchChartedForView(app: App, scope: Scope): void {
  let cancel = () => {};
  let told = "";
  watchState(app, scope, ["charted", "classroom", "demons", "large"], (now) => {
    const runId = now.selectedRunId;
    const demons = chartedDemons(now).slice(0, VIEW_DEMONS);
    const key = `${runId}|${demons.join(",")}|${now.large}`;
    if (runId === null || key === told || now.liveView.state !== "on") return;
    cancel();
    cancel = scope.after(TELL_VIEW_MS, () => {
      if (app.ui.state.selectedRunId !== runId) return; // another run was chosen meanwhile: it tells the view
      told = key;
      void attempt(app, () => showInLiveView(app, runId));
    });
  });
}

/** The job the Protocol tab shows, read four times a second while it runs; its end is told once. */
export function watchProtocol(app: App, scope: Scope): void {
  const statusOf = (jobId: string) => app.client.getQueryData<Protocol>(keys.protocol(jobId))?.status;
  let shown = app.ui.state.protocolId ?? "";
  let lastStatus = statusOf(shown);
  const watchOf = () => ({
    ...reads.protocol(shown),
    every: PROTOCOL_PERIOD_MS,
    enabled: statusOf(shown) === "running",
  });
  const onJob = (job: Protocol) => {
    if (job.id === shown && lastStatus === "running" && job.status !== "running") protocolEnded(app, job);
    if (job.id === shown) lastStatus = job.status;
    watcher.update(watchOf());
  };
  const onError = (error: unknown) => {
    if (error instanceof ApiError && error.status === 404 && app.ui.state.protocolId !== null) {
      // Forgotten by the server (another client cleared it, or the server restarted).
      notify(app, "The protocol job is gone from the server.", "error");
      app.ui.update({ protocolId: null, protocolStartedAt: null });
    }
    // Otherwise the server may be restarting; the next reading tries again.
  };
  const watcher = watchQuery(app.client, watchOf(), onJob, onError, scope);
  scope.add(
    app.ui.subscribe(() => {
      shown = app.ui.state.protocolId ?? "";
      lastStatus = statusOf(shown);
      watcher.update(watchOf());
    }, ["protocolId"]),
  );
}
