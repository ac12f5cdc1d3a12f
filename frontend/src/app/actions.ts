/**
 * Everything the dashboard asks of the server, each action updating the store with the answer.
 * Views call these and never talk to the API themselves (except the forms, which need the 422s).
 */
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import type { Demon, DemonSpec, Protocol, Run, RunBrief, RunTemplate } from "../api/types";
import { evaluationKind, gridWorld } from "../api/types";
import { startPoint } from "../lib/world";
import { keys, readNow } from "./queries";
import { type AppStore, chartedDemons } from "./state";
import { VIEWER_KEY } from "./viewer-key";

/** The live view labels and charts at most this many demons: the first charted ones. */
const VIEW_DEMONS = 12;

/** At most this many demons are charted when a run is selected; the user picks others in the table. */
const DEFAULT_CHARTED = 12;

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

/**
 * The scenarios and worlds, asked for again every `retryMs` until they arrive (each failure is shown as a
 * notice): the forms that launch from them wait for them, so one failed request must not leave them waiting.
 */
export async function loadCatalog(store: AppStore, retryMs = 3000): Promise<void> {
  const load = async () => {
    const [scenarios, worlds] = await Promise.all([unwrap(api.GET("/api/scenarios")), unwrap(api.GET("/api/worlds"))]);
    store.update({ scenarios, worlds, catalogLoaded: true });
    return true;
  };
  while ((await attempt(store, load)) === undefined) await new Promise((resolve) => setTimeout(resolve, retryMs));
}

export async function refreshWorlds(store: AppStore): Promise<void> {
  store.update({ worlds: await unwrap(api.GET("/api/worlds")) });
}

/** GET /api/runs: the runs' briefs (the query `keys.runs` that app/watch.ts polls). */
export function readRuns(): Promise<RunBrief[]> {
  return unwrap(api.GET("/api/runs"));
}

/** Take a reading of the run list into the store; a selected run that is gone is deselected. */
export function applyRuns(store: AppStore, runs: RunBrief[]): void {
  store.update({ runs });
  const selected = store.state.selectedRunId;
  if (selected !== null && !runs.some((r) => r.id === selected)) clearSelection(store);
}

/** Read the run list now, after a change: a reading under way (begun before the change) is dropped. */
export async function refreshRuns(store: AppStore): Promise<void> {
  applyRuns(store, await readNow(keys.runs, readRuns));
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
  const [run, demons, kept] = await Promise.all([
    unwrap(api.GET("/api/runs/{run_id}", path)),
    unwrap(api.GET("/api/runs/{run_id}/demons", path)),
    unwrap(api.GET("/api/runs/{run_id}/evaluations", path)),
  ]);
  // The run's kept evaluations (the latest of each demon) are shown again, after a reload or from a link.
  const evaluations = Object.fromEntries(kept.map((evaluation) => [evaluation.demon, evaluation]));
  store.update({ selectedRunId: runId, run, demons, live: null, evaluations, charted: defaultCharted(demons) });
  // The embedded live view follows; selecting never waits for it.
  void attempt(store, () => showInLiveView(store, runId));
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

/** PATCH /api/runs/{id} {hz}: steps per second, or null for full speed. */
export async function setRunSpeed(store: AppStore, runId: string, hz: number | null): Promise<void> {
  await unwrap(api.PATCH("/api/runs/{run_id}", { params: { path: { run_id: runId } }, body: { hz } }));
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

/** DELETE /api/runs/{id}/demons/{name}; a 409 (another demon or the behaviour reads it) is thrown. */
export async function removeDemon(store: AppStore, runId: string, demon: string): Promise<void> {
  await unwrap(api.DELETE("/api/runs/{run_id}/demons/{name}", { params: { path: { run_id: runId, name: demon } } }));
  if (store.state.selectedRunId === runId) {
    const evaluations = Object.fromEntries(Object.entries(store.state.evaluations).filter(([name]) => name !== demon));
    store.update({ evaluations, charted: store.state.charted.filter((name) => name !== demon) });
  }
  await reloadSelectedRun(store);
}

export async function deleteWorld(store: AppStore, name: string): Promise<void> {
  await unwrap(api.DELETE("/api/worlds/{name}", { params: { path: { name } } }));
  await refreshWorlds(store);
}

/** Monte-Carlo truth of a demon's question beside its prediction there: from the world's start point on the
 * grid world, from the run's current state on a world evaluated by rollouts (`evaluationKind`). */
export async function evaluateDemon(store: AppStore, demon: string, episodes: number): Promise<void> {
  const { selectedRunId: runId, run } = store.state;
  if (runId === null || run === null) return;
  const body =
    evaluationKind(run) === "grid"
      ? { demon, episodes, from: startPoint(gridWorld(run.spec.world) ?? {}) }
      : { demon, episodes };
  const evaluation = await unwrap(
    api.POST("/api/runs/{run_id}/evaluate", { params: { path: { run_id: runId } }, body }),
  );
  if (store.state.selectedRunId === runId) {
    store.update({ evaluations: { ...store.state.evaluations, [demon]: evaluation } });
  }
}

export function toggleCharted(store: AppStore, demon: string, on: boolean): void {
  const charted = store.state.charted.filter((name) => name !== demon);
  store.update({ charted: on ? [...charted, demon] : charted });
}

/**
 * Whether and where the viser live view listens (GET /api/view, at this page's own address: see
 * `VIEWER_KEY`); "off" when the server runs without it (only `horde serve` starts it) or cannot say.
 * Once on, it is switched to the selected run.
 */
export async function loadLiveView(store: AppStore): Promise<void> {
  try {
    const view = await unwrap(api.GET("/api/view", { params: { query: { viewer: VIEWER_KEY } } }));
    store.update({
      liveView:
        view.enabled && view.url
          ? { state: "on", url: view.url, run: view.run ?? null }
          : { state: "off", why: "this server runs without it (horde serve starts one)" },
    });
  } catch (error) {
    store.update({ liveView: { state: "off", why: `GET /api/view failed: ${errorMessage(error)}` } });
    return;
  }
  const view = store.state.liveView;
  const selected = store.state.selectedRunId;
  if (selected !== null && view.state === "on" && view.run !== selected) await showInLiveView(store, selected);
}

/**
 * Show a run in this page's live view (POST /api/view with its `VIEWER_KEY`, its Large text, and the page's
 * token, which the view then acts with); no other page's view changes. Nothing is asked while the view is
 * off or not known yet; a 409 (the view is off after all) or a 404 (the run was just deleted) is no news for
 * the user.
 */
export async function showInLiveView(store: AppStore, runId: string): Promise<void> {
  if (store.state.liveView.state !== "on") return;
  // The dashboard's choice of demons, once the run's demons are known (else the view's own first ones).
  const demons = store.state.selectedRunId === runId ? chartedDemons(store.state).slice(0, VIEW_DEMONS) : [];
  try {
    const body = { viewer: VIEWER_KEY, run: runId, large: store.state.large, ...(demons.length > 0 ? { demons } : {}) };
    const shown = await unwrap(api.POST("/api/view", { body }));
    const view = store.state.liveView;
    if (view.state === "on") store.update({ liveView: { ...view, run: shown.run ?? null } });
  } catch (error) {
    if (error instanceof ApiError && (error.status === 404 || error.status === 409)) return;
    throw error;
  }
}

/**
 * POST /api/protocols: run a scenario's protocol in the background; the Protocol tab shows the job.
 * Throws ApiError: 422 (the form shows it at the field), 429 (one protocol runs already).
 */
export async function startProtocol(store: AppStore, template: RunTemplate): Promise<Protocol> {
  const startedAt = Date.now();
  const job = await unwrap(api.POST("/api/protocols", { body: template }));
  store.update({ protocol: job, protocolStartedAt: startedAt });
  return job;
}

/** Read the shown job again (its progress, then its results). */
/** GET /api/protocols/{id}: one protocol job (the query `keys.protocol(id)` polled while it runs). */
export function readProtocol(jobId: string): Promise<Protocol> {
  return unwrap(api.GET("/api/protocols/{job_id}", { params: { path: { job_id: jobId } } }));
}

/** Take a reading of the shown protocol job into the store; its end is announced, its results kept. */
export function applyProtocol(store: AppStore, job: Protocol): void {
  const shown = store.state.protocol;
  if (shown?.id !== job.id) return;
  store.update({ protocol: job });
  if (shown.status === "running" && job.status !== "running") {
    // Its results join the table of every job.
    store.update({ protocols: [...store.state.protocols.filter((j) => j.id !== job.id), job] });
    const name = job.name ?? "the protocol";
    if (job.status === "failed") notify(store, `Protocol ${name} failed: ${job.error}`, "error");
    else notify(store, `Protocol ${name} ${job.status}.`);
  }
}

export async function refreshProtocol(store: AppStore): Promise<void> {
  const shown = store.state.protocol;
  if (shown === null) return;
  applyProtocol(store, await readProtocol(shown.id));
}

/** Ask the shown job to stop; it stops at its next episode (the status follows in the next reading). */
export async function cancelProtocol(store: AppStore): Promise<void> {
  const shown = store.state.protocol;
  if (shown === null || shown.status !== "running") return;
  const job = await unwrap(api.DELETE("/api/protocols/{job_id}", { params: { path: { job_id: shown.id } } }));
  if (store.state.protocol?.id === job.id) store.update({ protocol: job });
}

/**
 * The server's protocol jobs: the running one (or else the newest) is shown, so that a reloaded page
 * or a refused start (429) finds the job that runs. Returns the job shown, if any.
 */
export async function loadProtocols(store: AppStore): Promise<Protocol | null> {
  const jobs = await unwrap(api.GET("/api/protocols")); // oldest first
  store.update({ protocols: jobs });
  const job = jobs.filter((j) => j.status === "running").at(-1) ?? jobs.at(-1) ?? null;
  if (job !== null && job.id !== store.state.protocol?.id) {
    // Begun before this page knew of it: its elapsed time counts from the server's clock.
    const created = Date.parse(job.created_at);
    store.update({ protocol: job, protocolStartedAt: Number.isFinite(created) ? Math.min(created, Date.now()) : null });
  }
  return job;
}
