/**
 * Keeps the store current: the run list every second, the selected run's WebSocket stream, which
 * also notices when demons join or leave (the run is read again) and when it finishes, and the
 * protocol job while it runs (four readings a second: its progress, then its results).
 */
import { ApiError } from "../api/client";
import { RunStream } from "../api/stream";
import type { RunState } from "../api/types";
import { attempt, notify, refreshProtocol, refreshRuns, reloadSelectedRun } from "./actions";
import type { AppState, AppStore } from "./state";

const RUNS_PERIOD_MS = 1000;
const PROTOCOL_PERIOD_MS = 250;

export function watchRuns(store: AppStore): void {
  let busy = false;
  const tick = async () => {
    if (busy || document.hidden) return;
    busy = true;
    try {
      await refreshRuns(store);
    } catch {
      // The server may be restarting; the next tick tries again.
    } finally {
      busy = false;
    }
  };
  void tick();
  window.setInterval(tick, RUNS_PERIOD_MS);
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

function onMessage(store: AppStore, runId: string, message: RunState): void {
  const { selectedRunId, run, demons } = store.state;
  if (selectedRunId !== runId) return;
  store.update({ live: message });
  const names = Object.keys(message.predictions);
  const demonsChanged = names.length !== demons.length || demons.some((d) => !(d.name in message.predictions));
  // Compared with what was last read (not the previous message), so a change missed during a reading
  // is caught by the next message.
  const statusChanged = run !== null && run.status !== message.status;
  if ((demonsChanged || statusChanged) && !reloading) {
    reloading = true;
    void attempt(store, () => reloadSelectedRun(store)).finally(() => (reloading = false));
  }
}

export function watchProtocol(store: AppStore): void {
  let timer: number | undefined;
  const schedule = (state: Readonly<AppState>) => {
    if (timer === undefined && state.protocol?.status === "running")
      timer = window.setTimeout(poll, PROTOCOL_PERIOD_MS);
  };
  const poll = async () => {
    timer = undefined;
    try {
      await refreshProtocol(store);
    } catch (error) {
      if (error instanceof ApiError && error.status === 404) {
        // Forgotten by the server (another client cleared it, or the server restarted).
        notify(store, "The protocol job is gone from the server.", "error");
        store.update({ protocol: null, protocolStartedAt: null });
        return;
      }
      // The server may be restarting; the next reading tries again.
    }
    schedule(store.state);
  };
  store.subscribe(schedule, ["protocol"]);
  schedule(store.state);
}
