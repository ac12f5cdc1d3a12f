import { describe, expect, it, vi } from "vitest";
import { Store } from "../src/app/store";

describe("Store", () => {
  it("tells listeners which keys changed, and only when something did", () => {
    const store = new Store({ a: 1, b: "x" });
    const listener = vi.fn();
    store.subscribe(listener);
    store.update({ a: 1 });
    expect(listener).not.toHaveBeenCalled();
    store.update({ a: 2, b: "x" });
    expect(listener).toHaveBeenCalledTimes(1);
    expect([...listener.mock.calls[0]![1]]).toEqual(["a"]);
    expect(store.state).toEqual({ a: 2, b: "x" });
  });

  it("calls a keyed listener only for its keys, until it unsubscribes", () => {
    const store = new Store({ a: 1, b: "x" });
    const listener = vi.fn();
    const unsubscribe = store.subscribe(listener, ["b"]);
    store.update({ a: 5 });
    expect(listener).not.toHaveBeenCalled();
    store.update({ b: "y" });
    expect(listener).toHaveBeenCalledTimes(1);
    unsubscribe();
    store.update({ b: "z" });
    expect(listener).toHaveBeenCalledTimes(1);
  });
});
