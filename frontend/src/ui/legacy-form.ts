/**
 * Labelled form fields and the errors of a form: each field registers under the dotted path of the
 * request field it edits, so that a 422's problems appear next to the field they concern.
 */
import type { ValidationProblem } from "../api/types";
import { type Term, tip } from "../lib/glossary";
import { placeProblems } from "../lib/field-errors";
import { InputError } from "../lib/input-error";
import { h, replaceChildren, uid } from "./dom";

type Control = HTMLInputElement | HTMLSelectElement | HTMLTextAreaElement;

interface Slot {
  control: Control | null;
  message: HTMLElement;
}

const MAX_MESSAGES = 3;

export class FormErrors {
  private readonly slots = new Map<string, Slot>();
  /** Messages that concern the form as a whole; announced to screen readers. */
  readonly general = h("div", { class: "form-error", role: "alert", hidden: true });

  /** Register a field (or a group of fields) under `path`; returns its message element. */
  register(
    path: string,
    control: Control | null,
    message = h("p", { class: "field-error", id: uid("error") }),
  ): HTMLElement {
    message.hidden = true;
    const slot = { control, message };
    this.slots.set(path, slot);
    if (control) {
      control.setAttribute(
        "aria-describedby",
        [control.getAttribute("aria-describedby"), message.id].filter(Boolean).join(" "),
      );
      // A message about a value goes as soon as the value changes: it may be fixed now, and the next
      // submission says again if not.
      // Groups above it ("policy" above "policy.kind") speak of the value as a whole: they go too.
      const clearPath = () => this.clearField(path);
      control.addEventListener("input", clearPath);
      control.addEventListener("change", clearPath);
    }
    return message;
  }

  /** Clear the messages of the field registered under `path` and of the groups that hold it. */
  clearField(path: string): void {
    const parts = path.split(".");
    for (let length = parts.length; length > 0; length--) {
      const slot = this.slots.get(parts.slice(0, length).join("."));
      if (slot) this.clearSlot(slot);
    }
  }

  private clearSlot(slot: Slot): void {
    if (slot.message.hidden) return;
    slot.message.hidden = true;
    slot.message.textContent = "";
    slot.control?.removeAttribute("aria-invalid");
  }

  /** Forget the fields under `prefix` (a removed region). */
  unregister(prefix: string): void {
    for (const path of [...this.slots.keys()]) {
      if (path === prefix || path.startsWith(`${prefix}.`)) this.slots.delete(path);
    }
  }

  clear(): void {
    for (const slot of this.slots.values()) this.clearSlot(slot);
    this.general.hidden = true;
    this.general.textContent = "";
  }

  /** Show a 422's problems at their fields; the first field in error receives the focus. */
  showProblems(problems: readonly ValidationProblem[]): void {
    this.clear();
    const placed = placeProblems(problems, this.slots.keys());
    let first: Control | null = null;
    for (const [path, messages] of placed.byField) {
      const slot = this.slots.get(path);
      if (!slot) continue;
      this.showAt(slot, messages);
      first ??= slot.control;
    }
    if (placed.general.length > 0) this.showGeneral(placed.general.join(" · "));
    first?.focus();
  }

  /** Show one message at one field (a client-side problem, e.g. JSON that does not parse). */
  showField(path: string, message: string): void {
    const slot = this.slots.get(path);
    if (!slot) {
      this.showGeneral(message);
      return;
    }
    this.showAt(slot, [message]);
    slot.control?.focus();
  }

  /**
   * The form's value from `read`, or null once the InputError it threw (text that cannot be read at
   * all, e.g. JSON that does not parse) is shown at the field it names. Any other error is thrown on.
   */
  readOrShow<T>(read: () => T): T | null {
    try {
      return read();
    } catch (error) {
      if (!(error instanceof InputError)) throw error;
      this.showField(error.path, error.message);
      return null;
    }
  }

  showGeneral(message: string): void {
    this.general.hidden = false;
    this.general.textContent = message;
  }

  private showAt(slot: Slot, messages: string[]): void {
    const shown = messages.slice(0, MAX_MESSAGES);
    const more = messages.length - shown.length;
    replaceChildren(slot.message, shown.join(" · "), more > 0 ? ` (+${more} more)` : "");
    slot.message.hidden = false;
    slot.control?.setAttribute("aria-invalid", "true");
  }
}

export interface FieldOptions {
  /** the request field it edits, e.g. "policy.temperature"; registers it with `errors` */
  path?: string;
  errors?: FormErrors;
  hint?: string;
  class?: string;
  /** a word of the Horde papers: the label explains it in its tooltip */
  term?: Term;
}

/** A label, its control, an optional hint and the place for the field's error message. */
export function field(label: string, control: Control, opts: FieldOptions = {}): HTMLElement {
  control.id ||= uid("field");
  const hint = opts.hint ? h("p", { class: "hint", id: uid("hint") }, opts.hint) : null;
  if (hint) control.setAttribute("aria-describedby", hint.id);
  const message = opts.path && opts.errors ? opts.errors.register(opts.path, control) : null;
  return h(
    "div",
    { class: `field ${opts.class ?? ""}` },
    termLabel(label, control.id, opts.term),
    control,
    hint,
    message,
  );
}

/** A label; given a term, dotted and explained in its tooltip. */
export function termLabel(label: string, forId: string, term?: Term): HTMLLabelElement {
  return term
    ? h("label", { for: forId, title: tip(term) }, h("span", { class: "term" }, label))
    : h("label", { for: forId }, label);
}

/** A checkbox with its label after it. */
export function checkbox(label: string, input: HTMLInputElement): HTMLElement {
  input.type = "checkbox";
  input.id ||= uid("check");
  return h("div", { class: "field checkbox" }, input, h("label", { for: input.id }, label));
}

/**
 * The one entry of a list with nothing to choose yet: the catalogue is still on its way, or the server
 * has none. Its value is empty, so a form that launches from the list waits (its button is disabled).
 */
export function nothingToChoose(loaded: boolean, what: string): HTMLOptionElement {
  return h(
    "option",
    { value: "", disabled: true, selected: true },
    loaded ? `no ${what} on the server` : `loading the ${what}…`,
  );
}

/**
 * A number input that never blocks submission: no min/max/step checks in the browser, since the
 * server's 422 names the field and says why.
 */
export function numberInput(value: number | null | undefined, props: Record<string, unknown> = {}): HTMLInputElement {
  return h("input", { type: "number", step: "any", inputmode: "decimal", value: value ?? "", ...props });
}

export function textInput(value: string | null | undefined, props: Record<string, unknown> = {}): HTMLInputElement {
  return h("input", { type: "text", value: value ?? "", autocomplete: "off", spellcheck: "false", ...props });
}
