/**
 * What the views' lit-html templates share: a view's own element (`host`), the heading that names a
 * panel for screen readers, <option> lists, the dotted words the glossary explains, and names broken
 * only between their words.
 */
import { type TemplateResult, html, render } from "lit-html";
import { nameParts } from "../lib/format";
import { type Term, tip } from "../lib/glossary";

/**
 * A view's own element, from a template of one element (its tag, class and name for screen readers):
 * the view renders its content into it with `mount` (app/view.ts) or lit-html's `render`.
 */
export function host<E extends Element = HTMLElement>(template: TemplateResult): E {
  const box = document.createElement("div");
  render(template, box);
  const element = box.firstElementChild;
  if (element === null) throw new Error("host: the template holds no element");
  element.remove();
  return element as E;
}

/** What names a section: its heading's id and text, and what stands beside the heading. */
export interface Heading {
  /** The heading's id; the section is `aria-labelledby` it, so screen readers announce the title. */
  id: string;
  title: unknown;
  /** h2 for a dashboard panel (the default), h3 for a section inside one. */
  level?: "h2" | "h3";
  /** Controls in a `.panel-head` row beside the heading. */
  beside?: unknown;
}

/** A section's heading; with `beside`, in a `.panel-head` row with those controls. */
export function heading(head: Heading): TemplateResult {
  const title =
    head.level === "h3" ? html`<h3 id=${head.id}>${head.title}</h3>` : html`<h2 id=${head.id}>${head.title}</h2>`;
  return head.beside === undefined ? title : html`<div class="panel-head">${title}${head.beside}</div>`;
}

/** <option>s for a <select>: values, or [value, label] pairs; `selected` is chosen. */
export function choices(
  items: readonly (string | readonly [string, string])[],
  selected?: string | null,
): TemplateResult[] {
  return items.map((item) => {
    const [value, label] = typeof item === "string" ? [item, item] : item;
    return html`<option value=${value} .selected=${value === selected}>${label}</option>`;
  });
}

/** A word of the Horde papers (or its label): dotted, and explained in its tooltip. */
export function term(word: Term, label: unknown): TemplateResult {
  return html`<span class="term" title=${tip(word)}>${label}</span>`;
}

/** A demon's name, broken only between its words (at <wbr>, after "_"), never inside one. */
export function brokenName(name: string): unknown[] {
  return nameParts(name).map((part, i) => (i === 0 ? part : html`<wbr />${part}`));
}

let nextId = 0;
/** A document-unique id for label/for and aria-describedby pairs. */
export function uid(prefix: string): string {
  nextId += 1;
  return `${prefix}-${nextId}`;
}
