// @vitest-environment happy-dom
import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { createQueryClient, keys, readNow, watchQuery } from "../src/app/queries";

describe("watchQuery", () => {
  beforeEach(() => {
    vi.useFakeTimers();
  });
  afterEach(() => {
    vi.useRealTimers();
  });

  it("reads at once, then every interval, passing each answer on once, until stopped", async () => {
    const client = createQueryClient();
    let n = 0;
    const read = vi.fn(async () => ++n);
    const seen: number[] = [];
    const watcher = watchQuery(client, { queryKey: keys.runs, queryFn: read, every: 1000 }, (d) => seen.push(d));
    await vi.advanceTimersByTimeAsync(10);
    expect(seen).toEqual([1]);
    await vi.advanceTimersByTimeAsync(3000);
    expect(seen).toEqual([1, 2, 3, 4]);
    watcher.stop();
    await vi.advanceTimersByTimeAsync(5000);
    expect(read).toHaveBeenCalledTimes(4);
    expect(seen).toEqual([1, 2, 3, 4]);
  });

  it("reads nothing while disabled, and starts when enabled", async () => {
    const client = createQueryClient();
    const read = vi.fn(async () => "job");
    const seen: string[] = [];
    const watch = { queryKey: keys.protocol("a"), queryFn: read, every: 250 as const };
    const watcher = watchQuery(client, { ...watch, enabled: false }, (d) => seen.push(d));
    await vi.advanceTimersByTimeAsync(2000);
    expect(read).not.toHaveBeenCalled();
    watcher.update({ ...watch, enabled: true });
    await vi.advanceTimersByTimeAsync(600);
    expect(read.mock.calls.length).toBeGreaterThanOrEqual(3);
    expect(seen[0]).toBe("job");
    watcher.update({ ...watch, enabled: false });
    const calls = read.mock.calls.length;
    await vi.advanceTimersByTimeAsync(2000);
    expect(read).toHaveBeenCalledTimes(calls);
    watcher.stop();
  });

  it("reports a failed reading and tries again at the next interval", async () => {
    const client = createQueryClient();
    let fail = true;
    const read = vi.fn(async () => {
      if (fail) throw new Error("server restarting");
      return "back";
    });
    const data: string[] = [];
    const errors: string[] = [];
    const watcher = watchQuery(
      client,
      { queryKey: keys.studies, queryFn: read, every: 1000 },
      (d) => data.push(d),
      (e) => errors.push((e as Error).message),
    );
    await vi.advanceTimersByTimeAsync(10);
    expect(errors).toEqual(["server restarting"]);
    expect(data).toEqual([]);
    fail = false;
    await vi.advanceTimersByTimeAsync(1000);
    expect(data).toEqual(["back"]);
    watcher.stop();
  });

  it("reads once without an interval, shares a reading under way, and reads anew when asked to now", async () => {
    const client = createQueryClient();
    let n = 0;
    const read = vi.fn(async () => {
      await new Promise((resolve) => setTimeout(resolve, 50));
      return ++n;
    });
    const seen: number[] = [];
    const watcher = watchQuery(client, { queryKey: keys.runs, queryFn: read, every: false }, (d) => seen.push(d));
    await vi.advanceTimersByTimeAsync(100);
    expect(seen).toEqual([1]);
    await vi.advanceTimersByTimeAsync(10_000);
    expect(read).toHaveBeenCalledTimes(1); // no interval: read once
    const both = Promise.all([watcher.refetch(), watcher.refetch()]);
    await vi.advanceTimersByTimeAsync(100);
    await both;
    expect(read).toHaveBeenCalledTimes(2); // one reading for the two asks
    expect(seen).toEqual([1, 2]);
    // Reading now (after a change) drops a reading that began before it, and hands its answer to the
    // caller and to the watcher alike.
    const first = watcher.refetch();
    await vi.advanceTimersByTimeAsync(10);
    const again = readNow(client, { queryKey: keys.runs, queryFn: read });
    await vi.advanceTimersByTimeAsync(100);
    await first;
    expect(await again).toBe(4);
    expect(read).toHaveBeenCalledTimes(4);
    expect(seen.at(-1)).toBe(4);
    watcher.stop();
  });

  it("passes on the answers of a new key only, after the key changes", async () => {
    const client = createQueryClient();
    const seen: string[] = [];
    const watch = (id: string) => ({
      queryKey: keys.study(id),
      queryFn: async () => `study ${id}`,
      every: false as const,
    });
    const watcher = watchQuery(client, watch("a"), (d) => seen.push(d));
    await vi.advanceTimersByTimeAsync(10);
    watcher.update(watch("b"));
    await vi.advanceTimersByTimeAsync(10);
    expect(seen).toEqual(["study a", "study b"]);
    watcher.stop();
  });
});
