// @vitest-environment happy-dom
import { afterEach, describe, expect, it, vi } from "vitest";
import { createApp } from "../src/app/app";
import { Scope } from "../src/ui/scope";

const stream = {
  id: "abc123def456",
  name: "robot",
  sensors: ["light", "wheel", "heat"],
  actions: 2,
  demons: ["d1", "d2", "d3", "d4", "d5"],
  received: 12,
  learned: 11,
  predictions: {},
};

const asked: string[] = [];

function answer(url: string): unknown {
  if (url.endsWith("/api/streams")) return [stream];
  if (url.includes("/history")) return { records: [0], sensors: {}, predictions: {}, returns: {} };
  return {};
}

afterEach(() => {
  vi.unstubAllGlobals();
  asked.length = 0;
});

const until = async (check: () => boolean) => {
  for (let i = 0; i < 100 && !check(); i++) await new Promise((resolve) => setTimeout(resolve, 10));
  expect(check()).toBe(true);
};

describe("streamRuns", () => {
  it("lists stream runs and, once one is chosen, shows its strip with the first sensors and demons ticked", async () => {
    vi.stubGlobal(
      "ResizeObserver",
      class {
        observe() {}
        disconnect() {}
      },
    );
    vi.stubGlobal("fetch", async (input: Request | string) => {
      const url = typeof input === "string" ? input : input.url;
      asked.push(url);
      return new Response(JSON.stringify(answer(url)), {
        status: 200,
        headers: { "Content-Type": "application/json" },
      });
    });
    // openapi-fetch takes the global fetch when its client is made: import the view after stubbing it.
    const { streamRuns } = await import("../src/views/stream-runs");
    const app = createApp();
    const { list, strip } = streamRuns(app, new Scope());
    document.body.append(list, strip);
    expect(strip.hidden).toBe(true);
    await until(() => list.querySelector('li[data-stream="abc123def456"]') !== null);
    expect(list.textContent).toContain("robot · abc123");
    expect(list.textContent).toContain("11 records learned of 12 received");
    list.querySelector<HTMLButtonElement>('li[data-stream="abc123def456"] button')!.click();
    await until(() => !strip.hidden);
    expect(strip.querySelector("h2")!.textContent!.replace(/\s+/g, " ").trim()).toBe(
      "Stream run robot: predictions beside realised returns",
    );
    expect(strip.textContent!.replace(/\s+/g, " ")).toContain("No Evaluate here: a stream's records come from outside");
    const ticked = [...strip.querySelectorAll<HTMLInputElement>("input[type=checkbox]")]
      .filter((box) => box.checked)
      .map((box) => box.parentElement!.textContent!.trim());
    expect(ticked).toEqual(["light", "wheel", "heat", "d1", "d2", "d3", "d4"]);
    expect([...strip.querySelectorAll("figure")].map((f) => f.dataset.sensor ?? f.dataset.demon)).toEqual([
      "light",
      "wheel",
      "heat",
      "d1",
      "d2",
      "d3",
      "d4",
    ]);
    await until(() => asked.some((url) => url.includes("/api/streams/abc123def456/history")));
    const history = new URL(
      asked.find((url) => url.includes("/history"))!,
      "http://x",
    );
    expect(history.searchParams.get("sensors")).toBe("light,wheel,heat");
    expect(history.searchParams.get("demons")).toBe("d1,d2,d3,d4");
    // Choosing a grid run leaves the stream run.
    app.ui.update({ selectedRunId: "grid" });
    expect(strip.hidden).toBe(true);
    list.remove();
    strip.remove();
  });
});
