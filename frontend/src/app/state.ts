/** What the dashboard knows at one moment; the single store all views read. */
import type { Demon, Evaluation, Protocol, Run, RunBrief, RunState, Scenario, WorldRecord } from "../api/types";
import { Store } from "./store";

export type Tab = "live" | "protocol" | "world" | "demon" | "studies" | "lab";

/** The viser live view: not asked yet, off (the server has none, or it failed: why), or on. */
export type LiveView =
  { state: "unknown" } | { state: "off"; why: string } | { state: "on"; url: string; run: string | null };

export interface Notice {
  text: string;
  kind: "info" | "error";
}

export interface AppState {
  runs: RunBrief[];
  selectedRunId: string | null;
  /** the selected run in full (its spec: world, demons, thesis numbers) */
  run: Run | null;
  /** the selected run's demons: their specs and which are control demons */
  demons: Demon[];
  /** the newest stream message of the selected run */
  live: RunState | null;
  /** Monte-Carlo evaluations of the selected run's demons, by demon */
  evaluations: Record<string, Evaluation>;
  /** demons of the selected run shown on the charts */
  charted: string[];
  scenarios: Scenario[];
  worlds: WorldRecord[];
  /** whether the scenarios and worlds have arrived: until then the forms that launch from them wait */
  catalogLoaded: boolean;
  /** every protocol job the server keeps, oldest first (the Protocol tab's table of results) */
  protocols: Protocol[];
  /** the protocol job the Protocol tab shows (the server's latest answer about it) */
  protocol: Protocol | null;
  /** when that job began, by this browser's clock (ms since the epoch), for its elapsed time */
  protocolStartedAt: number | null;
  liveView: LiveView;
  tab: Tab;
  notice: Notice | null;
  /** classroom mode: every demon charted, the guided tour on offer */
  classroom: boolean;
  /** "Large text" for a projector: the page, the charts and the embedded view scale up */
  large: boolean;
}

export function createStore(): Store<AppState> {
  return new Store<AppState>({
    runs: [],
    selectedRunId: null,
    run: null,
    demons: [],
    live: null,
    evaluations: {},
    charted: [],
    scenarios: [],
    worlds: [],
    catalogLoaded: false,
    protocols: [],
    protocol: null,
    protocolStartedAt: null,
    liveView: { state: "unknown" },
    tab: "live",
    notice: null,
    classroom: false,
    large: false,
  });
}

export type AppStore = Store<AppState>;

/** Charts at most this many demons at once (the selection in the table picks among thousands). */
export const MAX_MULTIPLES = 48;

/** The demons to chart: every demon in classroom mode (the first MAX_MULTIPLES), else the ticked ones. */
export function chartedDemons(state: Readonly<AppState>): string[] {
  const names = state.classroom ? state.demons.map((d) => d.name) : state.charted;
  return names.slice(0, MAX_MULTIPLES);
}
