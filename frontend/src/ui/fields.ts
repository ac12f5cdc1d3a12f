/**
 * A form's plain fields listed once: each with the request field it edits (also the path its 422s
 * name), its label, how its text reads (a number, text, or a list of numbers), a hint, and the row it
 * stands in. From that one list the table draws the labelled inputs, fills them from a value, reads them
 * back, and keeps their texts (for Undo). The server validates what is read.
 */
import { type TemplateResult, html } from "lit-html";
import { type Ref, createRef } from "lit-html/directives/ref.js";
import type { Term } from "../lib/glossary";
import { formatList, readNumber, readNumberList } from "../lib/parse";
import { type FormErrors, numberField, textField, valueOf } from "./form";

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
  /** The labelled fields, row by row (each row a `div.row`), in the order of the list. */
  rows(): TemplateResult[];
  /** Write `values` into the inputs (a missing value leaves the input empty). */
  fill(values: Partial<Record<K, unknown>>): void;
  /** Read every input: numbers as numbers (NaN when empty, which the server refuses by name). */
  read(): Record<K, FieldValue>;
  /** The texts as typed, in the order of the list, and back. */
  texts(): string[];
  setTexts(texts: readonly string[]): void;
  /** The input of one field, once drawn. */
  input(key: K): HTMLInputElement | undefined;
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
  const refs = new Map<K, Ref<HTMLInputElement>>(specs.map((spec) => [spec.key, createRef<HTMLInputElement>()]));
  const refOf = (key: K) => refs.get(key) as Ref<HTMLInputElement>;
  const drawn = (spec: FieldSpec<K>) => {
    const path = prefix + spec.key;
    const options = { label: spec.label, path, errors, hint: spec.hint, term: spec.term };
    const input = { name: path, ref: refOf(spec.key) };
    return spec.kind === "number" ? numberField(options, input) : textField(options, input);
  };
  const setText = (key: K, text: string) => {
    const input = refOf(key).value;
    if (input) input.value = text;
  };
  return {
    rows: () => {
      const rows = [...new Set(specs.map((spec) => spec.row ?? 0))].sort((a, b) => a - b);
      return rows.map(
        (row) => html`<div class="row">${specs.filter((spec) => (spec.row ?? 0) === row).map(drawn)}</div>`,
      );
    },
    fill: (values) => {
      for (const spec of specs) setText(spec.key, textOf(spec.kind, values[spec.key]));
    },
    read: () => {
      const read = {} as Record<K, FieldValue>;
      for (const spec of specs) read[spec.key] = readText(spec.kind, valueOf(refOf(spec.key)));
      return read;
    },
    texts: () => specs.map((spec) => valueOf(refOf(spec.key))),
    setTexts: (texts) => specs.forEach((spec, i) => setText(spec.key, texts[i] ?? "")),
    input: (key) => refOf(key).value,
  };
}
