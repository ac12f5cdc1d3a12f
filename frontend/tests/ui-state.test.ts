import { describe, expect, it, vi } from "vitest";
import { UiStore } from "../src/app/ui-state";

describe("UiStore", () => {
  it("tells listeners which keys changed, and only when something did", () => {
    const store = new UiStore({ tab: "live" });
    const listener = vi.fn();
    store.subscribe(listener);
    store.update({ tab: "live" });
    expect(listener).not.toHaveBeenCalled();
    store.update({ tab: "world", classroom: false });
    expect(listener).toHaveBeenCalledTimes(1);
    expect([...listener.mock.calls[0]![1]]).toEqual(["tab"]);
    expect(store.state.tab).toBe("world");
  });

  it("calls a keyed listener only for its keys, until it unsubscribes", () => {
    const store = new UiStore();
    const listener = vi.fn();
    const unsubscribe = store.subscribe(listener, ["classroom"]);
    store.update({ tab: "world" });
    expect(listener).not.toHaveBeenCalled();
    store.update({ classroom: true });
    expect(listener).toHaveBeenCalledTimes(1);
    unsubscribe();
    expect(store.listenerCount).toBe(0);
    store.update({ classroom: false });
    expect(listener).toHaveBeenCalledTimes(1);
  });
});

describe("mergeWindow", () => {
  it("keeps the last known values of the demons a stream message leaves out", async () => {
    const { mergeWindow } = await import("../src/app/watch");
    const metric = (rupee: number) => ({ rupee, ude: 0, delta: 0, cumulant: 0, diverged: false });
    const base = {
      type: "state" as const,
      run: "r",
      status: "running" as const,
      message: "",
      hz: null,
      agent: { x: 0, y: 0 },
      episode: 0,
      step: 1,
      episode_step: 1,
      episode_return: 0,
      last_return: null,
      events: [],
      demon_total: 3,
    };
    const demons = [{ name: "a" }, { name: "b" }, { name: "c" }];
    const first = { ...base, predictions: { a: 1, b: 2 }, metrics: { a: metric(1), b: metric(2) } };
    const second = { ...base, step: 2, predictions: { c: 3, a: 10 }, metrics: { c: metric(3), a: metric(10) } };
    const merged = mergeWindow(mergeWindow(null, first, demons), second, demons);
    expect(merged.step).toBe(2);
    expect(merged.predictions).toEqual({ a: 10, b: 2, c: 3 });
    expect(Object.keys(merged.metrics)).toEqual(["a", "b", "c"]);
    // A message with every demon replaces what was known.
    const whole = { ...base, demon_total: 2, predictions: { a: 5, b: 6 }, metrics: {} };
    expect(mergeWindow(merged, whole, demons).predictions).toEqual({ a: 5, b: 6 });
  });
});
