// @vitest-environment happy-dom
import { afterEach, describe, expect, it, vi } from "vitest";
import type { Demon, Run, RunState } from "../src/api/types";
import { type App, createApp } from "../src/app/app";
import { keys } from "../src/app/queries";
import { MISSING } from "../src/lib/format";
import { Scope } from "../src/ui/scope";
import { demonTable } from "../src/views/demon-table";

const demon = (name: string, prediction: number): Demon =>
  ({
    name,
    colour: "#0072B2",
    control: false,
    prediction,
    metrics: { rupee: 0.1, ude: 0.2, diverged: false },
    spec: { name, policy: { kind: "uniform" }, cumulant: 1 },
  }) as unknown as Demon;

const run = { id: "abc123", name: "test", status: "running", spec: { world: {} } } as unknown as Run;

const state = (predictions: Record<string, number>): RunState =>
  ({ run: run.id, status: "running", step: 1, predictions, metrics: {}, demon_total: 0 }) as unknown as RunState;

/** The run selected, with `demons` and (optionally) a stream message, as the actions and the stream write them. */
function show(app: App, demons: Demon[], live?: RunState): void {
  app.client.setQueryData(keys.run(run.id), run);
  app.client.setQueryData(keys.demons(run.id), demons);
  if (live) app.client.setQueryData(keys.live(run.id), live);
  app.ui.update({ selectedRunId: run.id });
}

const rowOf = (table: HTMLElement, name: string) =>
  table.querySelector<HTMLTableRowElement>(`tr[data-demon="${name}"]`);

describe("demonTable", () => {
  it("keeps each demon's row (and the focus in it) while the stream changes its numbers", () => {
    const app = createApp();
    const table = demonTable(app, new Scope());
    document.body.append(table);
    show(app, [demon("a", 1), demon("b", 2)]);
    const rowA = rowOf(table, "a")!;
    expect(rowA.querySelectorAll("td")[0]!.textContent).toContain("1");
    const evaluate = rowA.querySelector<HTMLButtonElement>('button[aria-label="Evaluate a"]')!;
    evaluate.focus();
    show(app, [demon("a", 1), demon("b", 2)], state({ a: 7.25, b: 3 }));
    expect(rowOf(table, "a")).toBe(rowA);
    expect(rowA.querySelectorAll("td")[0]!.textContent).toContain("7.25");
    expect(document.activeElement).toBe(evaluate);
    table.remove();
  });

  it("moves rows with their demons when the order changes, and drops the rows of demons gone", () => {
    const app = createApp();
    const table = demonTable(app, new Scope());
    show(app, [demon("a", 1), demon("b", 2), demon("c", 3)]);
    const rowA = rowOf(table, "a");
    show(app, [demon("c", 3), demon("a", 1)]);
    expect([...table.querySelectorAll("tr[data-demon]")].map((tr) => tr.getAttribute("data-demon"))).toEqual([
      "c",
      "a",
    ]);
    expect(rowOf(table, "a")).toBe(rowA);
    expect(rowOf(table, "b")).toBeNull();
  });

  it("asks twice before removing a demon, and refuses on a finished run", () => {
    const app = createApp();
    const table = demonTable(app, new Scope());
    show(app, [demon("a", 1)]);
    const remove = table.querySelector<HTMLButtonElement>('button[aria-label="Remove a"]')!;
    remove.click();
    expect(remove.textContent?.trim()).toBe("Really remove?");
    // A stream message re-renders the row: the button stays armed.
    show(app, [demon("a", 1)], state({ a: 2 }));
    expect(table.querySelector('button[aria-label="Really remove a?"]')).toBe(remove);
    show(app, [demon("a", 1)], { ...state({ a: 2 }), status: "finished" });
    expect(remove.disabled).toBe(true);
  });

  it("shows each demon's latest RMSVE and RMSPBE beside RUPEE on a chain, and no such columns elsewhere", async () => {
    // The server's history: a chain run's rows carry rmsve and rmspbe; CartPole's have none (null).
    const rollouts = { kind: "rollouts", note: "" };
    const chain = { ...run, id: "chain1", evaluation: rollouts, spec: { world: { id: "horde/RandomWalk19-v0" } } };
    const cartPole = { ...run, id: "cartpole1", evaluation: rollouts, spec: { world: { id: "CartPole-v1" } } };
    const asked: string[] = [];
    vi.stubGlobal("fetch", async (input: Request | string) => {
      const url = typeof input === "string" ? input : input.url;
      asked.push(url);
      const demon = decodeURIComponent(url.split("/demons/")[1]!.split("/")[0]!);
      const errors = url.includes("chain1") ? { rmsve: [0.25], rmspbe: [demon === "a" ? 0.125 : null] } : {};
      const body = { demon, every: 1, capacity: 16, step: [9], prediction: [0], rmsve: null, rmspbe: null, ...errors };
      return new Response(JSON.stringify(body), { headers: { "content-type": "application/json" } });
    });
    const app = createApp();
    const table = demonTable(app, new Scope());
    const head = () => [...table.querySelectorAll("thead th")].map((th) => th.textContent?.trim());
    app.client.setQueryData(keys.run(chain.id), chain);
    app.client.setQueryData(keys.demons(chain.id), [demon("a", 1), demon("b", 2)]);
    app.ui.update({ selectedRunId: chain.id });
    await vi.waitFor(() => expect(head()).toContain("RMSVE"));
    expect(head()).toContain("RMSPBE");
    expect(table.querySelector('tr[data-demon="a"] [data-field="rmsve"]')?.textContent).toBe("0.250");
    expect(table.querySelector('tr[data-demon="a"] [data-field="rmspbe"]')?.textContent).toBe("0.125");
    expect(table.querySelector('tr[data-demon="b"] [data-field="rmspbe"]')?.textContent).toBe(MISSING);
    expect(asked.every((url) => url.includes("limit=1"))).toBe(true);
    // Another Gymnasium world records none: the history says so, and the columns go (absent, not 0).
    app.client.setQueryData(keys.run(cartPole.id), cartPole);
    app.client.setQueryData(keys.demons(cartPole.id), [demon("a", 1)]);
    app.ui.update({ selectedRunId: cartPole.id });
    await vi.waitFor(() => expect(asked.some((url) => url.includes("cartpole1"))).toBe(true));
    await vi.waitFor(() => expect(head()).not.toContain("RMSVE"));
    expect(table.querySelector('[data-field="rmsve"]')).toBeNull();
  });
});

afterEach(() => vi.unstubAllGlobals());
