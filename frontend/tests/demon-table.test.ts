// @vitest-environment happy-dom
import { describe, expect, it } from "vitest";
import type { Demon, Run, RunState } from "../src/api/types";
import { createStore } from "../src/app/state";
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

const rowOf = (table: HTMLElement, name: string) =>
  table.querySelector<HTMLTableRowElement>(`tr[data-demon="${name}"]`);

describe("demonTable", () => {
  it("keeps each demon's row (and the focus in it) while the stream changes its numbers", () => {
    const store = createStore();
    const table = demonTable(store);
    document.body.append(table);
    store.update({ selectedRunId: run.id, run, demons: [demon("a", 1), demon("b", 2)] });
    const rowA = rowOf(table, "a")!;
    expect(rowA.querySelectorAll("td")[0]!.textContent).toContain("1");
    const evaluate = rowA.querySelector<HTMLButtonElement>('button[aria-label="Evaluate a"]')!;
    evaluate.focus();
    store.update({ live: state({ a: 7.25, b: 3 }) });
    expect(rowOf(table, "a")).toBe(rowA);
    expect(rowA.querySelectorAll("td")[0]!.textContent).toContain("7.25");
    expect(document.activeElement).toBe(evaluate);
    table.remove();
  });

  it("moves rows with their demons when the order changes, and drops the rows of demons gone", () => {
    const store = createStore();
    const table = demonTable(store);
    store.update({ selectedRunId: run.id, run, demons: [demon("a", 1), demon("b", 2), demon("c", 3)] });
    const rowA = rowOf(table, "a");
    store.update({ demons: [demon("c", 3), demon("a", 1)] });
    expect([...table.querySelectorAll("tr[data-demon]")].map((tr) => tr.getAttribute("data-demon"))).toEqual([
      "c",
      "a",
    ]);
    expect(rowOf(table, "a")).toBe(rowA);
    expect(rowOf(table, "b")).toBeNull();
  });

  it("asks twice before removing a demon, and refuses on a finished run", () => {
    const store = createStore();
    const table = demonTable(store);
    store.update({ selectedRunId: run.id, run, demons: [demon("a", 1)] });
    const remove = table.querySelector<HTMLButtonElement>('button[aria-label="Remove a"]')!;
    remove.click();
    expect(remove.textContent).toBe("Really remove?");
    // A stream message re-renders the row: the button stays armed.
    store.update({ live: state({ a: 2 }) });
    expect(table.querySelector('button[aria-label="Really remove a?"]')).toBe(remove);
    store.update({ live: { ...state({ a: 2 }), status: "finished" } });
    expect(remove.disabled).toBe(true);
  });
});
