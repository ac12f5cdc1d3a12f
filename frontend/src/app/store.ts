/** A tiny observable store: components subscribe to the keys they show and re-render on change. */

export type Listener<S> = (state: Readonly<S>, changed: ReadonlySet<keyof S>) => void;

export class Store<S extends object> {
  private current: S;
  private readonly listeners = new Set<Listener<S>>();

  constructor(initial: S) {
    this.current = initial;
  }

  get state(): Readonly<S> {
    return this.current;
  }

  /** Merge `patch` into the state and tell the listeners which keys changed (by identity). */
  update(patch: Partial<S>): void {
    const changed = new Set<keyof S>();
    for (const key of Object.keys(patch) as (keyof S)[]) {
      if (this.current[key] !== patch[key]) changed.add(key);
    }
    if (changed.size === 0) return;
    this.current = { ...this.current, ...patch };
    for (const listener of this.listeners) listener(this.current, changed);
  }

  /** Call `listener` on every change of one of `keys` (all keys when none are given); returns an unsubscribe. */
  subscribe(listener: Listener<S>, keys?: readonly (keyof S)[]): () => void {
    const wrapped: Listener<S> = keys
      ? (state, changed) => keys.some((k) => changed.has(k)) && listener(state, changed)
      : listener;
    this.listeners.add(wrapped);
    return () => this.listeners.delete(wrapped);
  }
}
