/**
 * Keeps the store current: the run list every second, the selected run's WebSocket stream, which
 * also notices when demons join or leave (the run is read again) and when it finishes, and the
 * protocol job while it runs (four readings a second: its progress, then its results). The readings
 * are queries of app/queries.ts.
 */
import { ApiError } from "../api/client";
import { RunStream } from "../api/stream";
import type { RunState } from "../api/types";
import {
  applyProtocol,
  applyRuns,
  attempt,
  notify,
  readProtocol,
  readRuns,
  reloadSelectedRun,
  showInLiveView,
} from "./actions";
import { keys, queryClient, watchQuery } from "./queries";
import { type AppState, type AppStore, chartedDemons } from "./state";

const RUNS_PERIOD_MS = 1000;
const PROTOCOL_PERIOD_MS = 250;

export function watchRuns(store: AppStore): void {
  // A failed reading (the server may be restarting) is simply tried again at the next interval.
  watchQuery(queryClient, { queryKey: keys.runs, queryFn: readRuns, every: RUNS_PERIOD_MS }, (runs) =>
    applyRuns(store, runs),
  );
}

export function watchSelectedRun(store: AppStore): void {
  let stream: RunStream | null = null;
  store.subscribe(
    (state) => {
      stream?.close();
      stream = null;
      const runId = state.selectedRunId;
      if (runId === null) return;
      stream = new RunStream(
        runId,
        (message) => onMessage(store, runId, message),
        (reason) => notify(store, `The stream of run ${runId.slice(0, 6)} ended: ${reason}`),
      );
    },
    ["selectedRunId"],
  );
}

// One reading of the run at a time: messages keep coming (30 a second) while it is under way.
let reloading = false;

function onMessage(store: AppStore, runId: string, incoming: RunState): void {
  const { selectedRunId, run, demons, live } = store.state;
  if (selectedRunId !== runId) return;
  const message = mergeWindow(live, incoming, demons);
  store.update({ live: message });
  const total = incoming.demon_total || Object.keys(incoming.predictions).length;
  const known = demonNames(demons);
  const demonsChanged = total !== demons.length || Object.keys(incoming.predictions).some((name) => !known.has(name));
  // Compared with what was last read (not the previous message), so a change missed during a reading
  // is caught by the next message.
  const statusChanged = run !== null && run.status !== message.status;
  if ((demonsChanged || statusChanged) && !reloading) {
    reloading = true;
    void attempt(store, () => reloadSelectedRun(store)).finally(() => (reloading = false));
  }
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
export function watchChartedForView(store: AppStore): void {
  let timer: number | undefined;
  let told = "";
  store.subscribe(
    (state) => {
      const runId = state.selectedRunId;
      const key = `${runId}|${chartedDemons(state).slice(0, 12).join(",")}|${state.large}`;
      if (runId === null || key === told || state.liveView.state !== "on") return;
      window.clearTimeout(timer);
      timer = window.setTimeout(() => {
        told = key;
        void attempt(store, () => showInLiveView(store, runId));
      }, 300);
    },
    ["charted", "classroom", "demons", "large"],
  );
}

export function watchProtocol(store: AppStore): void {
  const watchOf = (state: Readonly<AppState>) => {
    const jobId = state.protocol?.id ?? "";
    return {
      queryKey: keys.protocol(jobId),
      queryFn: () => readProtocol(jobId),
      every: PROTOCOL_PERIOD_MS,
      enabled: state.protocol?.status === "running",
    };
  };
  const watcher = watchQuery(
    queryClient,
    watchOf(store.state),
    (job) => applyProtocol(store, job),
    (error) => {
      if (error instanceof ApiError && error.status === 404 && store.state.protocol !== null) {
        // Forgotten by the server (another client cleared it, or the server restarted).
        notify(store, "The protocol job is gone from the server.", "error");
        store.update({ protocol: null, protocolStartedAt: null });
      }
      // Otherwise the server may be restarting; the next reading tries again.
    },
  );
  store.subscribe((state) => watcher.update(watchOf(state)), ["protocol"]);
}
