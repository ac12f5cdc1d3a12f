/**
 * A read of the selected run that the Live tab follows (the charted histories, the demon table's state errors):
 * every `every` ms while the run runs, at once when one of the view's topics changes, and after a step of a
 * paused run (its step moved since the last reading).
 */
import type { Scope } from "../ui/scope";
import { type App, type AppState, type Topic, state, watchState } from "./app";
import { type Query, watchQuery } from "./queries";

export interface RunRead<T> {
  query: Query<T>;
  /** milliseconds between readings while the run runs */
  every: number;
  enabled: boolean;
}

/** Follow `readOf(now)`'s query, passing each answer to `onRead`; `onOff` is called when a change turns it off. */
export function followRunRead<T>(
  app: App,
  scope: Scope,
  topics: readonly Topic[],
  readOf: (now: AppState) => RunRead<T>,
  onRead: (data: T) => void,
  onOff: () => void = () => {},
): void {
  let readAtStep: number | null = null;
  const watchOf = (now: AppState) => {
    const { query, every, enabled } = readOf(now);
    return {
      queryKey: query.queryKey,
      queryFn: () => {
        readAtStep = state(app).live?.step ?? null;
        return query.queryFn();
      },
      every: now.live?.status === "running" ? every : (false as const),
      enabled,
    };
  };
  // A demon removed or a run deleted between two reads fails a reading: the next one catches up.
  const watcher = watchQuery(app.client, watchOf(state(app)), onRead, undefined, scope);
  watchState(app, scope, topics, (now) => {
    const watch = watchOf(now);
    if (!watch.enabled) onOff();
    watcher.update(watch);
    if (watch.enabled) void watcher.refetch();
  });
  watchState(app, scope, ["live"], (now) => {
    const watch = watchOf(now);
    watcher.update(watch);
    const step = now.live?.step ?? null;
    if (watch.enabled && now.live?.status !== "running" && step !== readAtStep) void watcher.refetch();
  });
}
