/**
 * Everything the dashboard reads from the server more than once goes through one @tanstack/query-core
 * client: a view or watcher observes a query (`watchQuery`), which refetches on its interval while it is
 * observed and enabled, pauses while the page is hidden, shares one reading under way between everyone
 * who asks, and reads again at once when an action that changed the data asks (`readNow`).
 */
import { QueryClient, QueryObserver, type QueryKey } from "@tanstack/query-core";

/** The keys of the queries, one place: an action invalidates by these prefixes. */
export const keys = {
  runs: ["runs"] as const,
  protocol: (jobId: string) => ["protocols", jobId] as const,
  histories: (runId: string, demons: readonly string[]) => ["histories", runId, ...demons] as const,
  studies: ["studies"] as const,
  study: (studyId: string) => ["studies", studyId] as const,
};

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

/** The dashboard's one query client. */
export const queryClient = createQueryClient();

export interface QueryWatch<T> {
  queryKey: QueryKey;
  queryFn: () => Promise<T>;
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
 * Observe one query: `onData` gets every new answer (once per answer, in order), `onError` every failed
 * reading. Returns the handle that changes, re-reads or stops it.
 */
export function watchQuery<T>(
  client: QueryClient,
  watch: QueryWatch<T>,
  onData: (data: T) => void,
  onError: (error: unknown) => void = () => {},
): Watcher<T> {
  const optionsOf = (w: QueryWatch<T>) => ({
    queryKey: w.queryKey,
    queryFn: w.queryFn,
    enabled: w.enabled ?? true,
    refetchInterval: w.every,
    // Structural sharing would hand back the previous object for an equal answer; each answer is
    // passed on as read (the store compares by identity, views by value).
    structuralSharing: false,
  });
  const observer = new QueryObserver<T, unknown, T, T, QueryKey>(client, optionsOf(watch));
  let seenData = 0;
  let seenError = 0;
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
  // Answers already in the cache under this key count as seen: only new readings are passed on.
  const current = observer.getCurrentResult();
  seenData = Math.max(seenData, current.dataUpdatedAt);
  seenError = Math.max(seenError, current.errorUpdatedAt);
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

/**
 * Read `key` now, after an action changed what it reads, and return the answer (its observers get it
 * too): a reading under way, which may have begun before the change, is dropped for a new one.
 */
export async function readNow<T>(key: QueryKey, read: () => Promise<T>, client: QueryClient = queryClient): Promise<T> {
  await client.cancelQueries({ queryKey: key });
  return client.fetchQuery({ queryKey: key, queryFn: read, staleTime: 0 });
}
