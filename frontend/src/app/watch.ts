/**
 * Keeps the store current: the run list every second, and the selected run's WebSocket stream,
 * which also notices when demons join or leave (the run is read again) and when it finishes.
 */
import { RunStream } from "../api/stream";
import type { RunState } from "../api/types";
import { attempt, notify, refreshRuns, reloadSelectedRun } from "./actions";
import type { AppStore } from "./state";

const RUNS_PERIOD_MS = 1000;

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
