// @vitest-environment happy-dom
import { afterEach, describe, expect, it, vi } from "vitest";
import { createApp } from "../src/app/app";
import { keys } from "../src/app/queries";

afterEach(() => {
  vi.unstubAllGlobals();
});

const until = async (check: () => boolean) => {
  for (let i = 0; i < 100 && !check(); i++) await new Promise((resolve) => setTimeout(resolve, 10));
  expect(check()).toBe(true);
};

describe("showInLiveView", () => {
  it("sends a page's switches one after the other, so that the last asked is the one the server shows", async () => {
    const sent: string[] = [];
    const answers: (() => void)[] = [];
    vi.stubGlobal("fetch", async (input: Request) => {
      const body = (await input.json()) as { run: string };
      sent.push(body.run);
      await new Promise<void>((resolve) => answers.push(resolve)); // held until the test answers
      return new Response(JSON.stringify({ enabled: true, url: "http://view", run: body.run }), {
        status: 200,
        headers: { "Content-Type": "application/json" },
      });
    });
    // openapi-fetch takes the global fetch when its client is made: import the actions after stubbing it.
    const { showInLiveView } = await import("../src/app/actions");
    const app = createApp();
    app.client.setQueryData(keys.view, { enabled: true, url: "http://view", run: null });

    const first = showInLiveView(app, "first");
    const second = showInLiveView(app, "second");
    await until(() => sent.length === 1);
    await new Promise((resolve) => setTimeout(resolve, 50));
    expect(sent).toEqual(["first"]); // the second waits for the first's answer
    answers[0]!();
    await first;
    await until(() => sent.length === 2);
    expect(sent).toEqual(["first", "second"]);
    answers[1]!();
    await second;
    expect(app.client.getQueryData<{ run: string }>(keys.view)?.run).toBe("second");
  });

  it("goes on with the next switch when one fails", async () => {
    const sent: string[] = [];
    vi.stubGlobal("fetch", async (input: Request) => {
      const body = (await input.json()) as { run: string };
      sent.push(body.run);
      const failed = body.run === "broken";
      return new Response(JSON.stringify(failed ? { detail: "boom" } : { enabled: true, url: "u", run: body.run }), {
        status: failed ? 500 : 200,
        headers: { "Content-Type": "application/json" },
      });
    });
    const { showInLiveView } = await import("../src/app/actions");
    const app = createApp();
    app.client.setQueryData(keys.view, { enabled: true, url: "u", run: null });
    await expect(showInLiveView(app, "broken")).rejects.toThrow();
    await showInLiveView(app, "after");
    expect(sent).toEqual(["broken", "after"]);
    expect(app.client.getQueryData<{ run: string }>(keys.view)?.run).toBe("after");
  });
});
