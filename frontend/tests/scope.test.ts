// @vitest-environment happy-dom
import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { Scope } from "../src/ui/scope";

describe("Scope", () => {
  beforeEach(() => vi.useFakeTimers());
  afterEach(() => vi.useRealTimers());

  it("releases what it took, the last first, once, and at once what is taken after it went", () => {
    const scope = new Scope();
    const order: string[] = [];
    scope.add(() => order.push("first"));
    scope.add(() => order.push("second"));
    scope.dispose();
    scope.dispose();
    expect(order).toEqual(["second", "first"]);
    expect(scope.disposed).toBe(true);
    scope.add(() => order.push("late"));
    expect(order).toEqual(["second", "first", "late"]);
  });

  it("stops its listeners, intervals and timeouts", () => {
    const scope = new Scope();
    const heard = vi.fn();
    const ticks = vi.fn();
    const late = vi.fn();
    scope.listen(window, "resize", heard);
    scope.every(100, ticks);
    scope.after(1000, late);
    window.dispatchEvent(new Event("resize"));
    vi.advanceTimersByTime(250);
    expect([heard.mock.calls.length, ticks.mock.calls.length]).toEqual([1, 2]);
    scope.dispose();
    window.dispatchEvent(new Event("resize"));
    vi.advanceTimersByTime(2000);
    expect([heard.mock.calls.length, ticks.mock.calls.length, late.mock.calls.length]).toEqual([1, 2, 0]);
    expect(vi.getTimerCount()).toBe(0);
  });

  it("releases a child with its parent, or alone, and then forgets it", () => {
    const parent = new Scope();
    const gone = vi.fn();
    const kept = vi.fn();
    const early = parent.child();
    early.add(gone);
    parent.child().add(kept);
    early.dispose();
    expect(gone).toHaveBeenCalledTimes(1);
    parent.dispose();
    expect(gone).toHaveBeenCalledTimes(1);
    expect(kept).toHaveBeenCalledTimes(1);
  });

  it("holds nothing of a child released early (a chart charted and uncharted a thousand times)", () => {
    const parent = new Scope();
    for (let i = 0; i < 1000; i++) parent.child().dispose();
    const releases = (parent as unknown as { releases: unknown[] }).releases;
    expect(releases).toHaveLength(0);
  });
});
