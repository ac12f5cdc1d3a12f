// @vitest-environment happy-dom
import { afterEach, describe, expect, it, vi } from "vitest";
import { createApp, state } from "../src/app/app";

afterEach(() => vi.unstubAllGlobals());

const json = (body: unknown, status = 200) =>
  new Response(JSON.stringify(body), { status, headers: { "Content-Type": "application/json" } });

describe("loadCatalog", () => {
  it("asks again after a failed request, shows the failure, and marks the catalogue loaded once it arrives", async () => {
    let scenarioAsks = 0;
    vi.stubGlobal("fetch", async (input: Request | string) => {
      const url = typeof input === "string" ? input : input.url;
      if (url.endsWith("/api/scenarios")) {
        scenarioAsks += 1;
        if (scenarioAsks === 1) return json({ detail: "the server is starting" }, 503);
        return json([{ name: "experiment1", description: "Exp. 1", error: null }]);
      }
      if (url.endsWith("/api/worlds")) return json([]);
      return json({});
    });
    // openapi-fetch takes the global fetch when its client is made: import after stubbing it.
    const { loadCatalog } = await import("../src/app/actions");
    const app = createApp();
    const notices: string[] = [];
    app.ui.subscribe(() => notices.push(app.ui.state.notice?.kind ?? ""), ["notice"]);

    await loadCatalog(app, 5);

    expect(scenarioAsks).toBe(2);
    expect(notices).toEqual(["error"]);
    expect(state(app).catalogLoaded).toBe(true);
    expect(state(app).scenarios.map((s) => s.name)).toEqual(["experiment1"]);
  });
});
