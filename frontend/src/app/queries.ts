/**
 * The one store of server data: a @tanstack/query-core client whose cache holds every answer the
 * dashboard has read (the run list, the selected run, its demons, its live stream messages, its kept
 * evaluations, the catalogue, protocol jobs, histories, studies, stream runs, who the page is, the Class
 * tab's cards and tokens), each under one key. A watcher observes a
 * query (`watchQuery`), which reads again on its interval while observed and enabled, pauses while the
 * page is hidden, and shares one reading under way between everyone who asks; an action that changed
 * the data reads it again at once (`readNow`) or writes what the server answered (`setQueryData`); views
 * re-render when the data under a key they show changes (`onData`). Entries nobody observes or holds
 * (`hold`) are dropped after a while, as query-core does.
 */
import { QueryClient, QueryObserver, type QueryKey } from "@tanstack/query-core";
import type { Scope } from "../ui/scope";

/** The keys of the queries, one place. The first part (the root) names the kind of data. */
export const keys = {
  runs: ["runs"] as const,
  run: (runId: string) => ["run", runId] as const,
  demons: (runId: string) => ["demons", runId] as const,
  /** the newest message of the run's WebSocket stream (written by the stream, never fetched) */
  live: (runId: string) => ["live", runId] as const,
  /** the Monte-Carlo evaluations of the run's demons, by demon: those the server kept (read when the run is
   * selected), then each one Evaluate makes */
  evaluations: (runId: string) => ["evaluations", runId] as const,
  scenarios: ["scenarios"] as const,
  /** the learners the server's registry declares (GET /api/learners) */
  learners: ["learners"] as const,
  worlds: ["worlds"] as const,
  view: ["view"] as const,
  protocols: ["protocols"] as const,
  protocol: (jobId: string) => ["protocol", jobId] as const,
  histories: (runId: string, demons: readonly string[]) => ["histories", runId, ...demons] as const,
  /** the demons' latest RMSVE and RMSPBE, from their histories' last rows (null: the run records none) */
  stateErrors: (runId: string, demons: readonly string[]) => ["state-errors", runId, ...demons] as const,
  streams: ["streams"] as const,
  streamHistory: (streamId: string, sensors: readonly string[], demons: readonly string[]) =>
    ["stream-history", streamId, sensors.join(","), demons.join(",")] as const,
  streamDemons: (streamId: string) => ["stream-demons", streamId] as const,
  studies: ["studies"] as const,
  study: (studyId: string) => ["study", studyId] as const,
  /** who this page acts as (GET /api/me) */
  me: ["me"] as const,
  /** every run as a Class tab card (GET /api/overview) */
  overview: ["overview"] as const,
  /** the teacher's issued tokens (GET /api/tokens) */
  tokens: ["tokens"] as const,
};

/** The kinds of data: the keys' first parts. */
export type Root =
  | "runs"
  | "run"
  | "demons"
  | "live"
  | "evaluations"
  | "scenarios"
  | "learners"
  | "worlds"
  | "view"
  | "protocols"
  | "protocol"
  | "histories"
  | "state-errors"
  | "streams"
  | "stream-history"
  | "stream-demons"
  | "studies"
  | "study"
  | "me"
  | "overview"
  | "tokens";

/** What a key reads: the key and the request that answers it. */
export interface Query<T> {
  queryKey: QueryKey;
  queryFn: () => Promise<T>;
}

export function createQueryClient(): QueryClient {
  const client = new QueryClient({
    defaultOptions: {
      // A failed reading is reported to the watcher and tried again at the next interval, not at once.
      queries: { retry: false, staleTime: 0, refetchOnWindowFocus: false, refetchOnReconnect: true },
    },
  });
  client.mount();
  return client;
}

export interface QueryWatch<T> extends Query<T> {
  /** milliseconds between readings while observed, or false for none (read once, and on invalidation) */
  every: number | false;
  /** false pauses the query: no reading, no interval (default true) */
  enabled?: boolean;
}

export interface Watcher<T> {
  /** Change what is watched (another key, enabled or not, another interval). */
  update(next: QueryWatch<T>): void;
  /** Read now (an answer under way is shared, not repeated). */
  refetch(): Promise<void>;
  /** Stop watching: no more readings, no more calls. */
  stop(): void;
}

/**
 * Observe one query: `onData` gets every new answer (once per answer, in order, also one an action
 * wrote), `onError` every failed reading. Returns the handle that changes, re-reads or stops it; given a
 * scope, it stops when the scope goes.
 */
export function watchQuery<T>(
  client: QueryClient,
  watch: QueryWatch<T>,
  onData: (data: T) => void,
  onError: (error: unknown) => void = () => {},
  scope?: Scope,
): Watcher<T> {
  const optionsOf = (w: QueryWatch<T>) => ({
    queryKey: w.queryKey,
    queryFn: w.queryFn,
    enabled: w.enabled ?? true,
    refetchInterval: w.every,
    // Structural sharing would hand back the previous object for an equal answer; each answer is
    // passed on as read (views compare by value where it matters).
    structuralSharing: false,
  });
  const observer = new QueryObserver<T, unknown, T, T, QueryKey>(client, optionsOf(watch));
  // Answers already in the cache under this key count as seen: only new readings are passed on.
  const cached = observer.getCurrentResult();
  let seenData = cached.dataUpdatedAt;
  let seenError = cached.errorUpdatedAt;
  const stop = observer.subscribe((result) => {
    if (result.dataUpdatedAt > seenData && result.data !== undefined) {
      seenData = result.dataUpdatedAt;
      onData(result.data);
    }
    if (result.errorUpdatedAt > seenError && result.error != null) {
      seenError = result.errorUpdatedAt;
      onError(result.error);
    }
  });
  scope?.add(stop);
  return {
    update: (next) => {
      const before = JSON.stringify(observer.options.queryKey);
      observer.setOptions(optionsOf(next));
      if (JSON.stringify(next.queryKey) !== before) {
        const now = observer.getCurrentResult();
        seenData = now.dataUpdatedAt;
        seenError = now.errorUpdatedAt;
      }
    },
    refetch: async () => {
      await observer.refetch({ cancelRefetch: false });
    },
    stop,
  };
}

/** Keep the entry under `key` in the cache while `scope` lives (observed, never read by this hold). */
export function hold(client: QueryClient, key: QueryKey, scope: Scope): void {
  const observer = new QueryObserver(client, { queryKey: key, enabled: false });
  scope.add(observer.subscribe(() => {}));
}

/**
 * Read `query` now, after an action changed what it reads, and return the answer (its observers get it
 * too): a reading under way, which may have begun before the change, is dropped for a new one.
 */
export async function readNow<T>(client: QueryClient, query: Query<T>): Promise<T> {
  await client.cancelQueries({ queryKey: query.queryKey });
  return client.fetchQuery({ queryKey: query.queryKey, queryFn: query.queryFn, staleTime: 0 });
}

/** Call `listener` whenever the data under one of `roots` changes (a reading, a write, a failure, a removal). */
export function onData(client: QueryClient, roots: readonly Root[], listener: () => void): () => void {
  const wanted = new Set<unknown>(roots);
  return client.getQueryCache().subscribe((event) => {
    if (!wanted.has(event.query.queryKey[0])) return;
    if (event.type === "removed" || (event.type === "updated" && ["success", "error"].includes(event.action.type))) {
      listener();
    }
  });
}
