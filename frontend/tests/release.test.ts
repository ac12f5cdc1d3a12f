// @vitest-environment happy-dom
// Every view releases what it holds when its scope goes (issue 29): the whole dashboard is drawn with a
// run selected, charted and streaming, a stream run shown and a protocol job running, the Class tab read
// (its cards and the teacher's tokens, a Revoke armed) and a run presented from a card, with the role's
// style sheet and the address kept (issue 28); then its scope is disposed, and nothing it took may remain:
// no UI-state listener, no query observed, no cache listener, no timer, no listener on the window or the
// document, no element observed, no socket open, no role style sheet, no present mode.
import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { keepRoleStyles, loadMe } from "../src/app/access";
import { createApp } from "../src/app/app";
import { keepAddress } from "../src/app/location";
import { keys } from "../src/app/queries";
import { watchApp } from "../src/app/watch";
import type { Demon, Protocol, Run } from "../src/api/types";
import { Scope } from "../src/ui/scope";
import { dashboard } from "../src/views/dashboard";

const RUN = "run1";
const STREAM = "stream1";
const demon = (name: string): Demon =>
  ({
    name,
    colour: "#0072B2",
    control: false,
    prediction: 1,
    metrics: { rupee: 0.1, ude: 0.2, diverged: false },
    spec: { name, policy: { kind: "uniform" }, cumulant: 1 },
  }) as unknown as Demon;
const brief = { id: RUN, name: "r", status: "running", step: 5, episode: 1, hz: 20, message: "", demons: ["a"] };
const run = { ...brief, spec: { world: {}, learning: { lambda: 0.9, alpha: 0.1, alpha_w: 0.01 } } } as unknown as Run;
const job = { id: "job1", name: "experiment1", status: "running", episodes_done: 1, episodes_total: 10 } as Protocol;
const history = { demon: "a", step: [1, 2, 3], prediction: [0, 1, 2], rupee: [], ude: [], delta: [], cumulant: [] };
const card = { ...brief, owner: "teacher", sparkline: { steps: [1, 2], series: { a: [0, 1] } } };
const token = { id: "tok1", name: "vic", role: "viewer", created_at: "2025-01-01T00:00:00Z" };
const stream = { id: STREAM, name: "s", sensors: ["x"], actions: 2, demons: ["d"], received: 3, learned: 3 };

function answer(url: string): unknown {
  const path = new URL(url, "http://x").pathname;
  if (path === "/api/runs") return [brief];
  if (path === `/api/runs/${RUN}`) return run;
  if (path === "/api/me") return { role: "teacher", name: "teacher", id: null, tokens: true };
  if (path === "/api/overview") return [card];
  if (path === "/api/tokens") return [token];
  if (path.endsWith("/evaluations")) return [];
  if (path.endsWith("/history") && path.startsWith("/api/runs")) return history;
  if (path === "/api/streams") return [stream];
  if (path.endsWith("/history")) return { records: [0, 1, 2], sensors: { x: [1, 2, 3] }, predictions: {}, returns: {} };
  if (path.endsWith("/demons")) return [demon("d")];
  if (path === "/api/view") return { enabled: true, url: "http://view", run: null };
  if (path.startsWith("/api/protocols/")) return job;
  if (path === "/api/studies" || path === "/api/scenarios" || path === "/api/worlds" || path === "/api/protocols")
    return [];
  return {};
}

/** What was taken and not given back, by kind. */
const held = { listeners: 0, observed: new Set<string>(), sockets: 0 };
let nextObserver = 0;

beforeEach(() => {
  vi.useFakeTimers({
    toFake: [
      "setTimeout",
      "clearTimeout",
      "setInterval",
      "clearInterval",
      "requestAnimationFrame",
      "cancelAnimationFrame",
    ],
  });
  vi.stubGlobal("fetch", async (input: Request | string) => {
    const url = typeof input === "string" ? input : input.url;
    return new Response(JSON.stringify(answer(url)), { status: 200, headers: { "Content-Type": "application/json" } });
  });
  vi.stubGlobal(
    "ResizeObserver",
    class {
      private readonly id = (nextObserver += 1);
      private readonly targets = new Set<Element>();
      observe(target: Element) {
        this.targets.add(target);
        held.observed.add(`${this.id}:${target.tagName}.${target.className}`);
      }
      unobserve(target: Element) {
        this.targets.delete(target);
        held.observed.delete(`${this.id}:${target.tagName}.${target.className}`);
      }
      disconnect() {
        for (const target of [...this.targets]) this.unobserve(target);
      }
    },
  );
  vi.stubGlobal(
    "WebSocket",
    class {
      static readonly CONNECTING = 0;
      static readonly OPEN = 1;
      readyState = 1;
      onopen: (() => void) | null = null;
      constructor() {
        held.sockets += 1;
      }
      close() {
        held.sockets -= 1;
        this.readyState = 3;
      }
    },
  );
  // happy-dom draws no canvas: the plots get a 2D context that does nothing.
  const nothing = new Proxy({}, { get: (_, key) => (key === "measureText" ? () => ({ width: 10 }) : () => {}) });
  vi.spyOn(HTMLCanvasElement.prototype, "getContext").mockReturnValue(nothing as CanvasRenderingContext2D);
  vi.stubGlobal(
    "Path2D",
    class {
      moveTo() {}
      lineTo() {}
      rect() {}
      arc() {}
      closePath() {}
      bezierCurveTo() {}
      addPath() {}
    },
  );
  for (const target of [window, document]) {
    const add = target.addEventListener.bind(target);
    const remove = target.removeEventListener.bind(target);
    vi.spyOn(target, "addEventListener").mockImplementation((type, listener, options) => {
      held.listeners += 1;
      add(type, listener, options);
    });
    vi.spyOn(target, "removeEventListener").mockImplementation((type, listener, options) => {
      held.listeners -= 1;
      remove(type, listener, options);
    });
  }
});

afterEach(() => {
  vi.restoreAllMocks();
  vi.unstubAllGlobals();
  vi.useRealTimers();
  document.body.replaceChildren();
});

describe("the dashboard's views", () => {
  it("release every subscription, observer, timer and socket when their scope goes", async () => {
    const app = createApp();
    app.client.unmount(); // query-core's own focus and online listeners are not the views'
    const scope = new Scope();
    const { page, help, tour } = dashboard(app, scope);
    document.body.append(page, help.element, tour.element);
    keepRoleStyles(app, scope);
    watchApp(app, scope);
    keepAddress(app, scope);
    await loadMe(app);
    // A run selected, charted and streaming; a protocol job running; a stream run shown.
    app.client.setQueryData(keys.run(RUN), run);
    // Enough demons for the table to keep only the rows in sight (its virtualizer watches the scroll box).
    const demons = [demon("a"), ...Array.from({ length: 70 }, (_, i) => demon(`d${i}`))];
    app.client.setQueryData(keys.demons(RUN), demons);
    app.client.setQueryData(keys.protocol(job.id), job);
    app.ui.update({ selectedRunId: RUN, charted: ["a"], protocolId: job.id, protocolStartedAt: 0 });
    await vi.advanceTimersByTimeAsync(2500);
    expect(page.querySelector(".table-scroll.virtual table.demon-table")).not.toBeNull();
    expect(page.querySelector('figure.chart[data-demon="a"]')).not.toBeNull();
    expect(held.sockets).toBe(1);
    page.querySelector<HTMLButtonElement>(`li[data-stream="${STREAM}"] button`)?.click();
    await vi.advanceTimersByTimeAsync(2500);
    expect(page.querySelector('figure.chart[data-sensor="x"]')).not.toBeNull();
    // The Class tab: the cards and the teacher's tokens read, a Revoke armed; then a card presented.
    app.ui.update({ tab: "class" });
    await vi.advanceTimersByTimeAsync(2500);
    expect(page.querySelector(`li.run-card[data-run="${RUN}"] polyline`)).not.toBeNull();
    page.querySelector<HTMLButtonElement>('tr[data-token="tok1"] button')?.click();
    await vi.advanceTimersByTimeAsync(10);
    expect(page.querySelector('tr[data-token="tok1"] button')?.textContent).toContain("Really revoke?");
    page.querySelector<HTMLButtonElement>(`li.run-card[data-run="${RUN}"] button[aria-label^="Present"]`)?.click();
    await vi.advanceTimersByTimeAsync(500);
    expect(document.documentElement.classList.contains("present")).toBe(true);
    expect(app.ui.state.tab).toBe("live");
    expect(document.getElementById("role-styles")).not.toBeNull();
    expect(held.listeners).toBeGreaterThan(0);
    expect(held.observed.size).toBeGreaterThan(0);
    expect(vi.getTimerCount()).toBeGreaterThan(0);

    scope.dispose();
    const cache = app.client.getQueryCache();
    const observed = (q: { getObserversCount: () => number }) => q.getObserversCount() > 0;
    expect(
      cache
        .getAll()
        .filter(observed)
        .map((q) => q.queryKey),
    ).toEqual([]);
    app.client.clear(); // the cache's own timers (dropping what nobody observes) go with its entries

    expect(app.ui.listenerCount).toBe(0);
    expect(cache.hasListeners()).toBe(false);
    expect(vi.getTimerCount()).toBe(0);
    expect(held.listeners).toBe(0);
    expect([...held.observed]).toEqual([]);
    expect(held.sockets).toBe(0);
    expect(document.documentElement.classList.contains("present")).toBe(false);
    expect(document.getElementById("role-styles")).toBeNull();
  });
});
