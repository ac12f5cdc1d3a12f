/**
 * Everything the dashboard asks of the server, each action updating the store with the answer.
 * Views call these and never talk to the API themselves (except the forms, which need the 422s).
 */
import { api, errorMessage, unwrap } from "../api/client";
import type { Demon, DemonSpec, Run, RunTemplate } from "../api/types";
import { startPoint } from "../lib/world";
import type { AppStore } from "./state";

/** At most this many demons are charted when a run is selected; the user picks others in the table. */
const DEFAULT_CHARTED = 3;

export function notify(store: AppStore, text: string, kind: "info" | "error" = "info"): void {
  store.update({ notice: { text, kind } });
}

/** Run `work`; on failure, show its message as an error notice (and return undefined). */
export async function attempt<T>(store: AppStore, work: () => Promise<T>): Promise<T | undefined> {
  try {
    return await work();
  } catch (error) {
    notify(store, errorMessage(error), "error");
    return undefined;
  }
}

export async function loadCatalog(store: AppStore): Promise<void> {
  const [scenarios, worlds] = await Promise.all([unwrap(api.GET("/api/scenarios")), unwrap(api.GET("/api/worlds"))]);
  store.update({ scenarios, worlds });
}

export async function refreshWorlds(store: AppStore): Promise<void> {
  store.update({ worlds: await unwrap(api.GET("/api/worlds")) });
}

export async function refreshRuns(store: AppStore): Promise<void> {
  const runs = await unwrap(api.GET("/api/runs"));
  store.update({ runs });
  const selected = store.state.selectedRunId;
  if (selected !== null && !runs.some((r) => r.id === selected)) clearSelection(store);
}

function clearSelection(store: AppStore): void {
  store.update({ selectedRunId: null, run: null, demons: [], live: null, evaluations: {}, charted: [] });
}

/** Prediction demons first: they answer questions worth charting; control demons steer. */
function defaultCharted(demons: Demon[]): string[] {
  const prediction = demons.filter((d) => !d.control).map((d) => d.name);
  const control = demons.filter((d) => d.control).map((d) => d.name);
  return [...prediction, ...control].slice(0, DEFAULT_CHARTED);
}

export async function selectRun(store: AppStore, runId: string | null): Promise<void> {
  if (runId === null) {
    clearSelection(store);
    return;
  }
  if (runId === store.state.selectedRunId) return;
  const path = { params: { path: { run_id: runId } } };
  const [run, demons] = await Promise.all([
    unwrap(api.GET("/api/runs/{run_id}", path)),
    unwrap(api.GET("/api/runs/{run_id}/demons", path)),
  ]);
  store.update({ selectedRunId: runId, run, demons, live: null, evaluations: {}, charted: defaultCharted(demons) });
}

/** Read the selected run and its demons again (a demon joined, the run finished). */
export async function reloadSelectedRun(store: AppStore): Promise<void> {
  const runId = store.state.selectedRunId;
  if (runId === null) return;
  const path = { params: { path: { run_id: runId } } };
  const [run, demons] = await Promise.all([
    unwrap(api.GET("/api/runs/{run_id}", path)),
    unwrap(api.GET("/api/runs/{run_id}/demons", path)),
  ]);
  if (store.state.selectedRunId !== runId) return;
  const names = new Set(demons.map((d) => d.name));
  store.update({ run, demons, charted: store.state.charted.filter((name) => names.has(name)) });
}

export type RunCommand = "start" | "pause" | "reset";

export async function commandRun(store: AppStore, runId: string, command: RunCommand): Promise<void> {
  const path = { params: { path: { run_id: runId } } };
  const done =
    command === "start"
      ? api.POST("/api/runs/{run_id}/start", path)
      : command === "pause"
        ? api.POST("/api/runs/{run_id}/pause", path)
        : api.POST("/api/runs/{run_id}/reset", path);
  await unwrap(done);
  if (command === "reset" && store.state.selectedRunId === runId) store.update({ evaluations: {} });
  await refreshRuns(store);
}

export async function stepRun(store: AppStore, runId: string, steps: number): Promise<void> {
  await unwrap(api.POST("/api/runs/{run_id}/step", { params: { path: { run_id: runId } }, body: { steps } }));
  await refreshRuns(store);
}

export async function deleteRun(store: AppStore, runId: string): Promise<void> {
  await unwrap(api.DELETE("/api/runs/{run_id}", { params: { path: { run_id: runId } } }));
  if (store.state.selectedRunId === runId) clearSelection(store);
  await refreshRuns(store);
}

/** POST /api/runs with a template; the new run is selected. Throws ApiError (the form shows 422s). */
export async function launchRun(
  store: AppStore,
  template: RunTemplate,
  hz: number | undefined,
  start: boolean,
): Promise<Run> {
  const run = await unwrap(api.POST("/api/runs", { body: template, params: { query: { hz, start } } }));
  await refreshRuns(store);
  await selectRun(store, run.id);
  return run;
}

/** POST /api/runs/{id}/demons; the demon is charted at once. Throws ApiError (the form shows 422s). */
export async function addDemon(store: AppStore, runId: string, spec: DemonSpec): Promise<Demon> {
  const demon = await unwrap(
    api.POST("/api/runs/{run_id}/demons", { params: { path: { run_id: runId } }, body: spec }),
  );
  await reloadSelectedRun(store);
  if (store.state.selectedRunId === runId && !store.state.charted.includes(demon.name)) {
    store.update({ charted: [...store.state.charted, demon.name] });
  }
  return demon;
}

/** Monte-Carlo truth of a demon's question from the world's start point, beside its prediction there. */
export async function evaluateDemon(store: AppStore, demon: string, episodes: number): Promise<void> {
  const { selectedRunId: runId, run } = store.state;
  if (runId === null || run === null) return;
  const from = startPoint(run.spec.world ?? {});
  const evaluation = await unwrap(
    api.POST("/api/runs/{run_id}/evaluate", { params: { path: { run_id: runId } }, body: { demon, from, episodes } }),
  );
  if (store.state.selectedRunId === runId) {
    store.update({ evaluations: { ...store.state.evaluations, [demon]: evaluation } });
  }
}

export function toggleCharted(store: AppStore, demon: string, on: boolean): void {
  const charted = store.state.charted.filter((name) => name !== demon);
  store.update({ charted: on ? [...charted, demon] : charted });
}
