/**
 * A form's plain fields listed once: each with the request field it edits (also the path its 422s
 * name), its label, how its text reads (a number, text, or a list of numbers), a hint, and the row it
 * stands in. From that one list the table builds the inputs and their labelled fields, fills them from
 * a value, reads them back, and keeps their texts (for Undo). The server validates what is read.
 */
import type { Term } from "../lib/glossary";
import { formatList, readNumber, readNumberList } from "../lib/parse";
import { h } from "./dom";
import { type FormErrors, field, numberInput, textInput } from "./legacy-form";

export type FieldKind = "number" | "text" | "numbers";

export interface FieldSpec<K extends string> {
  /** the request field; its 422s name `prefix + key` */
  key: K;
  label: string;
  kind: FieldKind;
  hint?: string;
  term?: Term;
  /** the row of the form it stands in (fields of one row side by side, rows in order) */
  row?: number;
}

export type FieldValue = number | string | number[];

export interface FieldTable<K extends string> {
  readonly inputs: Readonly<Record<K, HTMLInputElement>>;
  /** The labelled fields, row by row (each row a `div.row`), in the order of the list. */
  rows(): HTMLElement[];
  /** Write `values` into the inputs (a missing value leaves the input empty). */
  fill(values: Partial<Record<K, unknown>>): void;
  /** Read every input: numbers as numbers (NaN when empty, which the server refuses by name). */
  read(): Record<K, FieldValue>;
  /** The texts as typed, in the order of the list, and back. */
  texts(): string[];
  setTexts(texts: readonly string[]): void;
}

function textOf(kind: FieldKind, value: unknown): string {
  if (value === undefined || value === null) return "";
  if (kind === "numbers") return formatList(value as number[]);
  return String(value);
}

function readText(kind: FieldKind, text: string): FieldValue {
  if (kind === "number") return readNumber(text);
  if (kind === "numbers") return readNumberList(text);
  return text.trim();
}

export function fieldTable<K extends string>(
  specs: readonly FieldSpec<K>[],
  errors: FormErrors,
  prefix = "",
): FieldTable<K> {
  const inputs = {} as Record<K, HTMLInputElement>;
  for (const spec of specs) {
    const name = prefix + spec.key;
    inputs[spec.key] = spec.kind === "number" ? numberInput(null, { name }) : textInput("", { name });
  }
  return {
    inputs,
    rows: () => {
      const rows = new Map<number, HTMLElement[]>();
      for (const spec of specs) {
        const at = spec.row ?? 0;
        const made = field(spec.label, inputs[spec.key], {
          path: prefix + spec.key,
          errors,
          hint: spec.hint,
          term: spec.term,
        });
        rows.set(at, [...(rows.get(at) ?? []), made]);
      }
      return [...rows.keys()].sort((a, b) => a - b).map((at) => h("div", { class: "row" }, rows.get(at)));
    },
    fill: (values) => {
      for (const spec of specs) inputs[spec.key].value = textOf(spec.kind, values[spec.key]);
    },
    read: () => {
      const read = {} as Record<K, FieldValue>;
      for (const spec of specs) read[spec.key] = readText(spec.kind, inputs[spec.key].value);
      return read;
    },
    texts: () => specs.map((spec) => inputs[spec.key].value),
    setTexts: (texts) => specs.forEach((spec, i) => (inputs[spec.key].value = texts[i] ?? "")),
  };
}
