/**
 * The dashboard's own state, kept apart from what the server says (which lives in the query cache,
 * `app/queries.ts`): which run is selected and which of its demons are charted, the tab, the notice line,
 * the protocol job shown, classroom mode, large text and present mode. Small on purpose: nothing here is a copy of a
 * server answer. Views subscribe to the keys they show (through `app/view.ts`).
 */

export type Tab = "live" | "class" | "protocol" | "world" | "demon" | "studies";

/** Every tab, in the order the tab list shows them (the address names one: `?tab=`). */
export const TABS: readonly Tab[] = ["live", "class", "protocol", "world", "demon", "studies"];

export interface Notice {
  text: string;
  kind: "info" | "error";
}

export interface UiState {
  /** the run the Live tab shows (its data: `keys.run`, `keys.demons`, `keys.live`, `keys.evaluations`) */
  selectedRunId: string | null;
  /** demons of the selected run shown on the charts */
  charted: string[];
  /** the protocol job the Protocol tab shows (its data: `keys.protocol`) */
  protocolId: string | null;
  /** when that job began, by this browser's clock (ms since the epoch), for its elapsed time */
  protocolStartedAt: number | null;
  tab: Tab;
  notice: Notice | null;
  /** classroom mode: every demon charted, the guided tour on offer */
  classroom: boolean;
  /** "Large text" for a projector: the page, the charts and the embedded view scale up */
  large: boolean;
  /** present mode for a projector: the selected run's live view and charts large, the rest hidden */
  present: boolean;
}

export type UiKey = keyof UiState;
export type UiListener = (state: Readonly<UiState>, changed: ReadonlySet<UiKey>) => void;

export class UiStore {
  private current: UiState;
  private readonly listeners = new Set<UiListener>();

  constructor(initial: Partial<UiState> = {}) {
    this.current = {
      selectedRunId: null,
      charted: [],
      protocolId: null,
      protocolStartedAt: null,
      tab: "live",
      notice: null,
      classroom: false,
      large: false,
      present: false,
      ...initial,
    };
  }

  get state(): Readonly<UiState> {
    return this.current;
  }

  /** Merge `patch` into the state and tell the listeners which keys changed (by identity). */
  update(patch: Partial<UiState>): void {
    const changed = new Set<UiKey>();
    for (const key of Object.keys(patch) as UiKey[]) {
      if (this.current[key] !== patch[key]) changed.add(key);
    }
    if (changed.size === 0) return;
    this.current = { ...this.current, ...patch };
    for (const listener of [...this.listeners]) listener(this.current, changed);
  }

  /** Call `listener` on every change of one of `keys` (all keys when none are given); returns an unsubscribe. */
  subscribe(listener: UiListener, keys?: readonly UiKey[]): () => void {
    const wrapped: UiListener = keys
      ? (state, changed) => keys.some((k) => changed.has(k)) && listener(state, changed)
      : listener;
    this.listeners.add(wrapped);
    return () => this.listeners.delete(wrapped);
  }

  /** How many listeners are subscribed (a view that went must leave none behind). */
  get listenerCount(): number {
    return this.listeners.size;
  }
}
