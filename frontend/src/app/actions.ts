/**
 * Everything the dashboard asks of the server, each action writing the answer where it belongs: the
 * server's data into the query cache, the page's own choices (the selection, the charted demons, the
 * protocol job shown) into the UI state. Views call these and never talk to the API themselves (except
 * the forms, which need the 422s).
 */
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import type { Demon, DemonSpec, Evaluation, LiveViewInfo, Protocol, Run, RunBrief, RunTemplate } from "../api/types";
import { evaluationKind, gridWorld } from "../api/types";
import { startPoint } from "../lib/world";
import { type App, chartedDemons, state } from "./app";
import { keys, readNow } from "./queries";
import { reads } from "./reads";
import { VIEWER_KEY } from "./viewer-key";

/** The live view labels and charts at most this many demons: the first charted ones. */
export const VIEW_DEMONS = 12;

/** At most this many demons are charted when a run is selected; the user picks others in the table. */
const DEFAULT_CHARTED = 12;

export function notify(app: App, text: string, kind: "info" | "error" = "info"): void {
  app.ui.update({ notice: { text, kind } });
}

/** Run `work`; on failure, show its message as an error notice (and return undefined). */
export async function attempt<T>(app: App, work: () => Promise<T>): Promise<T | undefined> {
  try {
    return await work();
  } catch (error) {
    notify(app, errorMessage(error), "error");
    return undefined;
  }
}

/**
 * The scenarios and worlds, asked for again every `retryMs` until they arrive (each failure is shown as a
 * notice): the forms that launch from them wait for them, so one failed request must not leave them waiting.
 */
export async function loadCatalog(app: App, retryMs = 3000): Promise<void> {
  const load = async () => {
    await Promise.all([
      readNow(app.client, reads.scenarios()),
      readNow(app.client, reads.worlds()),
      readNow(app.client, reads.learners()),
    ]);
    return true;
  };
  while ((await attempt(app, load)) === undefined) await new Promise((resolve) => setTimeout(resolve, retryMs));
}

export async function refreshWorlds(app: App): Promise<void> {
  await readNow(app.client, reads.worlds());
}

/** A reading of the run list (app/watch.ts polls it): a selected run that is gone is deselected. */
export function applyRuns(app: App, runs: RunBrief[]): void {
  const selected = app.ui.state.selectedRunId;
  if (selected !== null && !runs.some((r) => r.id === selected)) clearSelection(app);
}

/** Read the run list now, after a change: a reading under way (begun before the change) is dropped. */
export async function refreshRuns(app: App): Promise<void> {
  applyRuns(app, await readNow(app.client, reads.runs()));
}

function clearSelection(app: App): void {
  app.ui.update({ selectedRunId: null, charted: [] });
}

/** Prediction demons first: they answer questions worth charting; control demons steer. */
function defaultCharted(demons: Demon[]): string[] {
  const prediction = demons.filter((d) => !d.control).map((d) => d.name);
  const control = demons.filter((d) => d.control).map((d) => d.name);
  return [...prediction, ...control].slice(0, DEFAULT_CHARTED);
}

/** Read a run and its demons into the cache. */
async function readRun(app: App, runId: string): Promise<[Run, Demon[]]> {
  return Promise.all([readNow(app.client, reads.run(runId)), readNow(app.client, reads.demons(runId))]);
}

export async function selectRun(app: App, runId: string | null): Promise<void> {
  if (runId === null) {
    clearSelection(app);
    return;
  }
  if (runId === app.ui.state.selectedRunId) return;
  // The run's kept evaluations (the latest of each demon) are shown again, after a reload or from a link.
  const [[, demons]] = await Promise.all([readRun(app, runId), readNow(app.client, reads.evaluations(runId))]);
  // A run selected again starts afresh: no stream message yet.
  app.client.setQueryData(keys.live(runId), null);
  app.ui.update({ selectedRunId: runId, charted: defaultCharted(demons) });
  // The embedded live view follows; selecting never waits for it.
  void attempt(app, () => showInLiveView(app, runId));
}

/** Read the selected run and its demons again (a demon joined, the run finished). */
export async function reloadSelectedRun(app: App): Promise<void> {
  const runId = app.ui.state.selectedRunId;
  if (runId === null) return;
  const [, demons] = await readRun(app, runId);
  if (app.ui.state.selectedRunId !== runId) return;
  const names = new Set(demons.map((d) => d.name));
  app.ui.update({ charted: app.ui.state.charted.filter((name) => names.has(name)) });
}

export type RunCommand = "start" | "pause" | "reset";

export async function commandRun(app: App, runId: string, command: RunCommand): Promise<void> {
  const path = { params: { path: { run_id: runId } } };
  const done =
    command === "start"
      ? api.POST("/api/runs/{run_id}/start", path)
      : command === "pause"
        ? api.POST("/api/runs/{run_id}/pause", path)
        : api.POST("/api/runs/{run_id}/reset", path);
  await unwrap(done);
  if (command === "reset") app.client.setQueryData(keys.evaluations(runId), {});
  await refreshRuns(app);
}

export async function stepRun(app: App, runId: string, steps: number): Promise<void> {
  await unwrap(api.POST("/api/runs/{run_id}/step", { params: { path: { run_id: runId } }, body: { steps } }));
  await refreshRuns(app);
}

/** PATCH /api/runs/{id} {hz}: steps per second, or null for full speed. */
export async function setRunSpeed(app: App, runId: string, hz: number | null): Promise<void> {
  await unwrap(api.PATCH("/api/runs/{run_id}", { params: { path: { run_id: runId } }, body: { hz } }));
  await refreshRuns(app);
}

export async function deleteRun(app: App, runId: string): Promise<void> {
  await unwrap(api.DELETE("/api/runs/{run_id}", { params: { path: { run_id: runId } } }));
  if (app.ui.state.selectedRunId === runId) clearSelection(app);
  await refreshRuns(app);
}

/** POST /api/runs with a template; the new run is selected. Throws ApiError (the form shows 422s). */
export async function launchRun(app: App, template: RunTemplate, hz: number | undefined, start: boolean): Promise<Run> {
  const run = await unwrap(api.POST("/api/runs", { body: template, params: { query: { hz, start } } }));
  await refreshRuns(app);
  await selectRun(app, run.id);
  return run;
}

/** POST /api/runs/{id}/demons; the demon is charted at once. Throws ApiError (the form shows 422s). */
export async function addDemon(app: App, runId: string, spec: DemonSpec): Promise<Demon> {
  const demon = await unwrap(
    api.POST("/api/runs/{run_id}/demons", { params: { path: { run_id: runId } }, body: spec }),
  );
  await reloadSelectedRun(app);
  const { selectedRunId, charted } = app.ui.state;
  if (selectedRunId === runId && !charted.includes(demon.name)) app.ui.update({ charted: [...charted, demon.name] });
  return demon;
}

/** DELETE /api/runs/{id}/demons/{name}; a 409 (another demon or the behaviour reads it) is thrown. */
export async function removeDemon(app: App, runId: string, demon: string): Promise<void> {
  await unwrap(api.DELETE("/api/runs/{run_id}/demons/{name}", { params: { path: { run_id: runId, name: demon } } }));
  // Uncharted first: the charts must not read the history of a demon that is gone.
  if (app.ui.state.selectedRunId === runId) {
    app.ui.update({ charted: app.ui.state.charted.filter((name) => name !== demon) });
  }
  app.client.setQueryData<Record<string, Evaluation>>(keys.evaluations(runId), (evaluations = {}) =>
    Object.fromEntries(Object.entries(evaluations).filter(([name]) => name !== demon)),
  );
  await reloadSelectedRun(app);
}

export async function deleteWorld(app: App, name: string): Promise<void> {
  await unwrap(api.DELETE("/api/worlds/{name}", { params: { path: { name } } }));
  await refreshWorlds(app);
}

/** Monte-Carlo truth of a demon's question beside its prediction there: from the world's start point on the
 * grid world, from the run's current state on a world evaluated by rollouts (`evaluationKind`). */
export async function evaluateDemon(app: App, demon: string, episodes: number): Promise<void> {
  const { selectedRunId: runId, run } = state(app);
  if (runId === null || run === null) return;
  const body =
    evaluationKind(run) === "grid"
      ? { demon, episodes, from: startPoint(gridWorld(run.spec.world) ?? {}) }
      : { demon, episodes };
  const evaluation = await unwrap(
    api.POST("/api/runs/{run_id}/evaluate", { params: { path: { run_id: runId } }, body }),
  );
  app.client.setQueryData<Record<string, Evaluation>>(keys.evaluations(runId), (evaluations = {}) => ({
    ...evaluations,
    [demon]: evaluation,
  }));
}

export function toggleCharted(app: App, demon: string, on: boolean): void {
  const charted = app.ui.state.charted.filter((name) => name !== demon);
  app.ui.update({ charted: on ? [...charted, demon] : charted });
}

/**
 * Whether and where the viser live view listens (GET /api/view, at this page's own address: see
 * `VIEWER_KEY`); "off" when the server runs without it (only `horde serve` starts it) or cannot say.
 * Once on, it is switched to the selected run.
 */
export async function loadLiveView(app: App): Promise<void> {
  try {
    await readNow(app.client, reads.view());
  } catch {
    return; // the failure stays in the cache: the view is off, and says why
  }
  const view = state(app).liveView;
  const selected = app.ui.state.selectedRunId;
  if (selected !== null && view.state === "on" && view.run !== selected) await showInLiveView(app, selected);
}

/**
 * Show a run in this page's live view (POST /api/view with its `VIEWER_KEY`, its Large text, and the page's
 * token, which the view then acts with); no other page's view changes. Nothing is asked while the view is
 * off or not known yet; a 409 (the view is off after all) or a 404 (the run was just deleted) is no news for
 * the user. A page's switches are sent one after the other, each once the last is answered: two in flight at
 * once (the page's first switch, as the view comes on, and a click) could reach the server in either order,
 * and the view would stay on the run chosen first.
 */
export function showInLiveView(app: App, runId: string): Promise<void> {
  const shown = (switches.get(app) ?? Promise.resolve()).then(() => switchLiveView(app, runId));
  switches.set(
    app,
    shown.catch(() => undefined),
  );
  return shown;
}

/** The last switch of each page's live view asked for (`showInLiveView`). */
const switches = new WeakMap<App, Promise<void>>();

async function switchLiveView(app: App, runId: string): Promise<void> {
  const now = state(app);
  if (now.liveView.state !== "on") return;
  // The dashboard's choice of demons, once the run's demons are known (else the view's own first ones).
  const labelled = now.selectedRunId === runId ? chartedDemons(now).slice(0, VIEW_DEMONS) : [];
  try {
    const body = {
      viewer: VIEWER_KEY,
      run: runId,
      large: now.large,
      ...(labelled.length > 0 ? { demons: labelled } : {}),
    };
    const shown = await unwrap(api.POST("/api/view", { body }));
    app.client.setQueryData<LiveViewInfo>(keys.view, (view) => view && { ...view, run: shown.run ?? null });
  } catch (error) {
    if (error instanceof ApiError && (error.status === 404 || error.status === 409)) return;
    throw error;
  }
}

/**
 * POST /api/protocols: run a scenario's protocol in the background; the Protocol tab shows the job.
 * Throws ApiError: 422 (the form shows it at the field), 429 (one protocol runs already).
 */
export async function startProtocol(app: App, template: RunTemplate): Promise<Protocol> {
  const startedAt = Date.now();
  const job = await unwrap(api.POST("/api/protocols", { body: template }));
  app.client.setQueryData(keys.protocol(job.id), job);
  app.ui.update({ protocolId: job.id, protocolStartedAt: startedAt });
  return job;
}

/** A job has ended (finished, failed or cancelled): its results join the table of every job, and it is told. */
export function protocolEnded(app: App, job: Protocol): void {
  app.client.setQueryData<Protocol[]>(keys.protocols, (jobs = []) => [...jobs.filter((j) => j.id !== job.id), job]);
  const name = job.name ?? "the protocol";
  if (job.status === "failed") notify(app, `Protocol ${name} failed: ${job.error}`, "error");
  else notify(app, `Protocol ${name} ${job.status}.`);
}

/** Ask the shown job to stop; it stops at its next episode (the status follows in the next reading). */
export async function cancelProtocol(app: App): Promise<void> {
  const shown = state(app).protocol;
  if (shown === null || shown.status !== "running") return;
  const job = await unwrap(api.DELETE("/api/protocols/{job_id}", { params: { path: { job_id: shown.id } } }));
  app.client.setQueryData(keys.protocol(job.id), job);
}

/**
 * The server's protocol jobs: the running one (or else the newest) is shown, so that a reloaded page
 * or a refused start (429) finds the job that runs. Returns the job shown, if any.
 */
export async function loadProtocols(app: App): Promise<Protocol | null> {
  const jobs = await readNow(app.client, reads.protocols()); // oldest first
  const job = jobs.filter((j) => j.status === "running").at(-1) ?? jobs.at(-1) ?? null;
  if (job !== null && job.id !== app.ui.state.protocolId) {
    // Begun before this page knew of it: its elapsed time counts from the server's clock.
    const created = Date.parse(job.created_at);
    app.client.setQueryData(keys.protocol(job.id), job);
    app.ui.update({
      protocolId: job.id,
      protocolStartedAt: Number.isFinite(created) ? Math.min(created, Date.now()) : null,
    });
  }
  return job;
}
