/**
 * What a view holds while it lives (subscriptions, listeners on the window, timers, observers, charts),
 * each released when the view goes: `scope.dispose()` releases them all, the last taken first. A part
 * of a view that goes on its own (a chart of a demon no longer charted) takes a `child()` scope, released
 * with it or before it. Releasing twice is harmless; what is taken after the scope went is released at
 * once.
 */
export class Scope {
  private releases: (() => void)[] = [];
  private gone = false;

  /** True once released: a late answer (a request under way) must not draw into a view that went. */
  get disposed(): boolean {
    return this.gone;
  }

  /** Release `release` with the scope (an unsubscribe, a `stop`, a `destroy`). */
  add(release: () => void): void {
    if (this.gone) release();
    else this.releases.push(release);
  }

  /** `target.addEventListener(type, listener)` until the scope goes. */
  listen<E extends Event = Event>(
    target: EventTarget,
    type: string,
    listener: (event: E) => void,
    options?: AddEventListenerOptions,
  ): void {
    const handler = listener as EventListener;
    target.addEventListener(type, handler, options);
    this.add(() => target.removeEventListener(type, handler, options));
  }

  /** `fn` every `ms` milliseconds until the scope goes. */
  every(ms: number, fn: () => void): void {
    const timer = setInterval(fn, ms);
    this.add(() => clearInterval(timer));
  }

  /** `fn` once after `ms` milliseconds, unless the scope goes first; returns a cancel. */
  after(ms: number, fn: () => void): () => void {
    const timer = setTimeout(fn, ms);
    const cancel = () => clearTimeout(timer);
    this.add(cancel);
    return cancel;
  }

  /** `fn` whenever `element` changes size, until the scope goes. */
  resized(element: Element, fn: () => void): void {
    const observer = new ResizeObserver(fn);
    observer.observe(element);
    this.add(() => observer.disconnect());
  }

  /** A scope released with this one, or earlier by its own `dispose` (which then forgets it here). */
  child(): Scope {
    const child = new Scope();
    const release = () => child.dispose();
    this.add(release);
    child.add(() => {
      const at = this.releases.indexOf(release);
      if (at >= 0) this.releases.splice(at, 1);
    });
    return child;
  }

  /** Release everything, the last taken first. */
  dispose(): void {
    if (this.gone) return;
    this.gone = true;
    const releases = this.releases;
    this.releases = [];
    for (const release of releases.reverse()) release();
  }
}
