/**
 * The dashboard's two kinds of state and how a view reads them: the server's data in the query cache
 * (`app/queries.ts`, the one store of what the server said) and the page's own small UI state
 * (`app/ui-state.ts`). `state(app)` reads both as one `AppState` at the moment it is called (nothing is
 * copied from one into the other), and `watchState` calls a view back when a part it names changes.
 */
import type { QueryClient } from "@tanstack/query-core";
import type {
  Demon,
  Evaluation,
  LiveViewInfo,
  Me,
  Protocol,
  Run,
  RunBrief,
  RunState,
  Scenario,
  WorldRecord,
} from "../api/types";
import { errorMessage } from "../api/client";
import type { Scope } from "../ui/scope";
import type { LearnerInfo } from "../lib/learners";
import { type Root, createQueryClient, keys, onData } from "./queries";
import { type UiKey, type UiState, UiStore } from "./ui-state";

export type { Notice, Tab } from "./ui-state";
export { TABS } from "./ui-state";

export interface App {
  /** the page's own state */
  ui: UiStore;
  /** the server's data */
  client: QueryClient;
}

export function createApp(client: QueryClient = createQueryClient(), ui: UiStore = new UiStore()): App {
  return { ui, client };
}

/** The viser live view: not asked yet, off (the server has none, or it failed: why), or on. */
export type LiveView =
  { state: "unknown" } | { state: "off"; why: string } | { state: "on"; url: string; run: string | null };

/** What the dashboard knows at one moment: the UI state, and the server data it selects. */
export interface AppState extends UiState {
  runs: RunBrief[];
  /** the selected run in full (its spec: world, demons, thesis numbers) */
  run: Run | null;
  /** the selected run's demons: their specs and which are control demons */
  demons: Demon[];
  /** the newest stream message of the selected run */
  live: RunState | null;
  /** Monte-Carlo evaluations of the selected run's demons, by demon */
  evaluations: Record<string, Evaluation>;
  scenarios: Scenario[];
  worlds: WorldRecord[];
  /** the learners a demon can choose, as the server's registry declares them (GET /api/learners) */
  learners: LearnerInfo[];
  /** whether the scenarios and worlds have arrived: until then the forms that launch from them wait */
  catalogLoaded: boolean;
  /** every protocol job the server keeps, oldest first (the Protocol tab's table of results) */
  protocols: Protocol[];
  /** the protocol job the Protocol tab shows (the server's latest answer about it) */
  protocol: Protocol | null;
  liveView: LiveView;
  /** who this page acts as (GET /api/me); null until known */
  me: Me | null;
}

export type Topic = keyof AppState;

// One empty value of each kind, so that "nothing yet" keeps its identity from one reading to the next.
const NONE: never[] = [];
const NO_EVALUATIONS: Record<string, Evaluation> = {};
const UNKNOWN: LiveView = { state: "unknown" };

function liveViewOf(client: QueryClient): LiveView {
  const { data, error } = client.getQueryState<LiveViewInfo>(keys.view) ?? {};
  if (data) {
    return data.enabled && data.url
      ? { state: "on", url: data.url, run: data.run ?? null }
      : { state: "off", why: "this server runs without it (horde serve starts one)" };
  }
  if (error) return { state: "off", why: `GET /api/view failed: ${errorMessage(error)}` };
  return UNKNOWN;
}

/** The state now: the UI state, and the server data of the selected run and job, read from the cache. */
export function state({ ui, client }: App): AppState {
  const u = ui.state;
  const read = <T>(key: readonly unknown[]): T | undefined => client.getQueryData<T>(key);
  const runId = u.selectedRunId;
  const scenarios = read<Scenario[]>(keys.scenarios);
  const worlds = read<WorldRecord[]>(keys.worlds);
  return {
    ...u,
    runs: read<RunBrief[]>(keys.runs) ?? NONE,
    run: runId === null ? null : (read<Run>(keys.run(runId)) ?? null),
    demons: runId === null ? NONE : (read<Demon[]>(keys.demons(runId)) ?? NONE),
    live: runId === null ? null : (read<RunState | null>(keys.live(runId)) ?? null),
    evaluations: runId === null ? NO_EVALUATIONS : (read(keys.evaluations(runId)) ?? NO_EVALUATIONS),
    scenarios: scenarios ?? NONE,
    learners: read<LearnerInfo[]>(keys.learners) ?? NONE,
    worlds: worlds ?? NONE,
    catalogLoaded: scenarios !== undefined && worlds !== undefined,
    protocols: read<Protocol[]>(keys.protocols) ?? NONE,
    protocol: u.protocolId === null ? null : (read<Protocol>(keys.protocol(u.protocolId)) ?? null),
    liveView: liveViewOf(client),
    me: read<Me>(keys.me) ?? null,
  };
}

/** Where each part of the state comes from: the UI keys and the kinds of server data it follows. */
const SOURCES: Record<Topic, { ui?: UiKey[]; data?: Root[] }> = {
  selectedRunId: { ui: ["selectedRunId"] },
  charted: { ui: ["charted"] },
  protocolId: { ui: ["protocolId"] },
  protocolStartedAt: { ui: ["protocolStartedAt"] },
  tab: { ui: ["tab"] },
  notice: { ui: ["notice"] },
  classroom: { ui: ["classroom"] },
  large: { ui: ["large"] },
  present: { ui: ["present"] },
  runs: { data: ["runs"] },
  run: { ui: ["selectedRunId"], data: ["run"] },
  demons: { ui: ["selectedRunId"], data: ["demons"] },
  live: { ui: ["selectedRunId"], data: ["live"] },
  evaluations: { ui: ["selectedRunId"], data: ["evaluations"] },
  scenarios: { data: ["scenarios"] },
  learners: { data: ["learners"] },
  worlds: { data: ["worlds"] },
  catalogLoaded: { data: ["scenarios", "worlds"] },
  protocols: { data: ["protocols"] },
  protocol: { ui: ["protocolId"], data: ["protocol"] },
  liveView: { data: ["view"] },
  me: { data: ["me"] },
};

/**
 * Call `listener` with the state whenever one of `topics` may have changed, until `scope` goes.
 * (A change of the data of a run that is not selected calls it too: views compare what they show.)
 */
export function watchState(
  app: App,
  scope: Scope,
  topics: readonly Topic[],
  listener: (state: AppState) => void,
): void {
  const uiKeys = new Set<UiKey>();
  const roots = new Set<Root>();
  for (const topic of topics) {
    for (const key of SOURCES[topic].ui ?? []) uiKeys.add(key);
    for (const root of SOURCES[topic].data ?? []) roots.add(root);
  }
  const call = () => listener(state(app));
  if (uiKeys.size > 0) scope.add(app.ui.subscribe(call, [...uiKeys]));
  if (roots.size > 0) scope.add(onData(app.client, [...roots], call));
}

/** Charts at most this many demons at once (the selection in the table picks among thousands). */
export const MAX_MULTIPLES = 48;

/** The demons to chart: every demon in classroom mode (the first MAX_MULTIPLES), else the ticked ones. */
export function chartedDemons(state: Pick<AppState, "classroom" | "demons" | "charted">): string[] {
  const names = state.classroom ? state.demons.map((d) => d.name) : state.charted;
  return names.slice(0, MAX_MULTIPLES);
}
