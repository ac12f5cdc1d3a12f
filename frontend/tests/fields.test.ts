// @vitest-environment happy-dom
import { html, render } from "lit-html";
import { describe, expect, it } from "vitest";
import type { ValidationProblem } from "../src/api/types";
import { InputError } from "../src/lib/input-error";
import { type FieldSpec, fieldTable } from "../src/ui/fields";
import { FormErrors } from "../src/ui/form";

type Key = "name" | "start" | "width" | "slip";
const SPECS: readonly FieldSpec<Key>[] = [
  { key: "name", label: "Name", kind: "text", row: 0 },
  { key: "start", label: "Start", kind: "numbers", hint: "x, y", row: 0 },
  { key: "width", label: "Width", kind: "number", row: 1 },
  { key: "slip", label: "Slip", kind: "number", row: 1 },
];

/** A form holding the table's rows, drawn again whenever its errors change (as a view does). */
function form(prefix = "") {
  const root = document.createElement("form");
  document.body.append(root);
  const errors: FormErrors = new FormErrors(root, () => draw());
  const table = fieldTable(SPECS, errors, prefix);
  const draw = () => render(html`${table.rows()}`, root);
  draw();
  const rows = () => [...root.querySelectorAll<HTMLElement>("div.row")];
  return { root, errors, table, rows };
}

describe("fieldTable", () => {
  it("fills the inputs from a value and reads the same value back", () => {
    const { table } = form();
    table.fill({ name: "room", start: [50, 50], width: 500, slip: 0 });
    expect(table.input("start")?.value).toBe("50, 50");
    expect(table.input("slip")?.value).toBe("0");
    expect(table.read()).toEqual({ name: "room", start: [50, 50], width: 500, slip: 0 });
  });

  it("reads what the user typed as the server should judge it: trimmed text, NaN for an empty number", () => {
    const { table } = form();
    table.fill({ name: "room" });
    table.input("name")!.value = "  room 2 ";
    table.input("start")!.value = "10 20,30";
    const read = table.read();
    expect(read.name).toBe("room 2");
    expect(read.start).toEqual([10, 20, 30]);
    expect(Number.isNaN(read.width)).toBe(true);
  });

  it("keeps the texts as typed, in the list's order, and puts them back (Undo)", () => {
    const { table } = form();
    table.fill({ name: "a", start: [1, 2], width: 3, slip: 0.5 });
    const texts = table.texts();
    expect(texts).toEqual(["a", "1, 2", "3", "0.5"]);
    table.fill({});
    expect(table.texts()).toEqual(["", "", "", ""]);
    table.setTexts(texts);
    expect(table.read()).toEqual({ name: "a", start: [1, 2], width: 3, slip: 0.5 });
  });

  it("lays the fields out by row, each labelled, and shows a 422 at the field it names (under the prefix)", () => {
    const { errors, table, rows } = form("world.");
    expect(rows().map((row) => [...row.querySelectorAll("label")].map((l) => l.textContent))).toEqual([
      ["Name", "Start"],
      ["Width", "Slip"],
    ]);
    expect(table.input("width")?.name).toBe("world.width");
    const problem: ValidationProblem = {
      loc: ["body", "world", "slip"],
      msg: "Input should be less than 1",
      type: "x",
    };
    errors.showProblems([problem]);
    const slipField = rows()[1]!.querySelectorAll(".field")[1]!;
    const message = slipField.querySelector(".field-error") as HTMLElement;
    expect(message.hidden).toBe(false);
    expect(message.textContent).toContain("1");
    expect(table.input("slip")?.getAttribute("aria-invalid")).toBe("true");
    expect(table.input("slip")?.getAttribute("aria-describedby")).toContain(message.id);
    expect(document.activeElement).toBe(table.input("slip"));
    const widthMessage = rows()[1]!.querySelectorAll(".field")[0]!.querySelector(".field-error") as HTMLElement;
    expect(widthMessage.hidden).toBe(true);
  });

  it("clears a field's message when it is typed in, through the form's onInput", () => {
    const { root, errors, table } = form();
    root.addEventListener("input", errors.onInput);
    errors.showProblems([{ loc: ["body", "width"], msg: "Input should be greater than 0", type: "x" }]);
    const input = table.input("width")!;
    expect(input.getAttribute("aria-invalid")).toBe("true");
    input.dispatchEvent(new Event("input", { bubbles: true }));
    expect(input.getAttribute("aria-invalid")).toBeNull();
    expect(root.querySelector<HTMLElement>(".field-error:not([hidden])")).toBeNull();
  });

  it("reads a form or shows why it cannot be read at the field, and lets other errors through", () => {
    const { errors, table, rows } = form();
    expect(errors.readOrShow(() => table.read())?.name).toBe("");
    const bad = errors.readOrShow(() => {
      throw new InputError("width", "Not JSON: {");
    });
    expect(bad).toBeNull();
    const message = rows()[1]!.querySelector(".field-error") as HTMLElement;
    expect(message.hidden).toBe(false);
    expect(message.textContent).toContain("Not JSON");
    expect(() =>
      errors.readOrShow(() => {
        throw new TypeError("a bug");
      }),
    ).toThrow("a bug");
  });
});
