/** A small hyperscript helper: elements from a tag, properties and children, without a framework. */

export type Child = Node | string | number | null | undefined | false | Child[];

type Handler = (event: Event) => void;
export interface Props {
  [key: string]: unknown;
}

/**
 * `h("button", {class: "primary", onclick: go, "aria-label": "Start"}, "Start")`.
 * `on*` functions become listeners, `class`/`text`/`value`/`checked`/`disabled`/`hidden`/`selected`
 * are set as properties, `dataset` fills data-* attributes, and anything else is an attribute
 * (false, null and undefined leave it out).
 */
export function h<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  props: Props = {},
  ...children: Child[]
): HTMLElementTagNameMap[K] {
  const element = document.createElement(tag);
  applyProps(element, props);
  append(element, children);
  return element;
}

const SVG_NS = "http://www.w3.org/2000/svg";

/** The same for SVG elements (all props are attributes). */
export function s<K extends keyof SVGElementTagNameMap>(
  tag: K,
  props: Props = {},
  ...children: Child[]
): SVGElementTagNameMap[K] {
  const element = document.createElementNS(SVG_NS, tag);
  for (const [key, value] of Object.entries(props)) {
    if (value !== false && value !== null && value !== undefined) element.setAttribute(key, String(value));
  }
  append(element, children);
  return element;
}

const PROPERTIES = new Set(["value", "checked", "disabled", "hidden", "selected", "indeterminate"]);

function applyProps(element: HTMLElement, props: Props): void {
  for (const [key, value] of Object.entries(props)) {
    if (key.startsWith("on") && typeof value === "function") {
      element.addEventListener(key.slice(2), value as Handler);
    } else if (key === "class") {
      element.className = String(value ?? "");
    } else if (key === "text") {
      element.textContent = String(value ?? "");
    } else if (key === "dataset") {
      Object.assign(element.dataset, value);
    } else if (PROPERTIES.has(key)) {
      (element as unknown as Record<string, unknown>)[key] = value;
    } else if (value !== false && value !== null && value !== undefined) {
      element.setAttribute(key, value === true ? "" : String(value));
    }
  }
}

export function append(parent: Node, children: Child[]): void {
  for (const child of children) {
    if (child === null || child === undefined || child === false) continue;
    if (Array.isArray(child)) append(parent, child);
    else parent.appendChild(typeof child === "object" ? child : document.createTextNode(String(child)));
  }
}

/** Replace all children of `parent`. */
export function replaceChildren(parent: Element, ...children: Child[]): void {
  parent.replaceChildren();
  append(parent, children);
}

/** Set text only when it changed (keeps screen readers and selections calm at 30 updates a second). */
export function setText(element: Element, text: string): void {
  if (element.textContent !== text) element.textContent = text;
}

let nextId = 0;
/** A document-unique id for label/for and aria-describedby pairs. */
export function uid(prefix: string): string {
  nextId += 1;
  return `${prefix}-${nextId}`;
}

/** Options for a <select>: values, or [value, label] pairs. */
export function options(
  items: readonly (string | readonly [string, string])[],
  selected?: string,
): HTMLOptionElement[] {
  return items.map((item) => {
    const [value, label] = typeof item === "string" ? [item, item] : item;
    return h("option", { value, selected: value === selected }, label);
  });
}

/** What names a section: its class, its heading's id and text, and what stands beside the heading. */
export interface Heading {
  class: string;
  /** The heading's id; the section is `aria-labelledby` it, so screen readers announce the title. */
  id: string;
  title: Child;
  /** h2 for a dashboard panel (the default), h3 for a section inside one. */
  level?: "h2" | "h3";
  /** Controls in a `.panel-head` row beside the heading. */
  beside?: Child[];
  hidden?: boolean;
}

/** `<section class aria-labelledby=id><h2 id>title</h2>…children</section>`: a section named by its heading. */
export function section(head: Heading, ...children: Child[]): HTMLElement {
  const heading = h(head.level ?? "h2", { id: head.id }, head.title);
  const top = head.beside ? h("div", { class: "panel-head" }, heading, ...head.beside) : heading;
  return h("section", { class: head.class, "aria-labelledby": head.id, hidden: head.hidden }, top, ...children);
}
