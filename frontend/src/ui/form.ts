/**
 * Labelled form fields (lit-html templates) and the errors of a form: each field stands under the
 * dotted path of the request field it edits, so that a 422's problems appear next to the field they
 * concern. Validation stays on the server; a form only shows what it says.
 *
 * Either the inputs keep what is typed (it stays in them between renders): the form reads them through
 * lit-html refs and writes them only when it fills itself (a scenario chosen); or the form keeps it in its
 * own state (`bound`), where it fills, copies and re-indexes (the demon editor, the world's regions).
 */
import { type TemplateResult, html, noChange, nothing } from "lit-html";
import { live } from "lit-html/directives/live.js";
import { ifDefined } from "lit-html/directives/if-defined.js";
import { type Ref, ref } from "lit-html/directives/ref.js";
import type { ValidationProblem } from "../api/types";
import { placeProblems } from "../lib/field-errors";
import { type Term, tip } from "../lib/glossary";
import { InputError } from "../lib/input-error";
import { uid } from "./html";

const MAX_MESSAGES = 3;

/** The messages a form shows, by field path, and the one for the form as a whole. */
export class FormErrors {
  /** The prefix of the ids of the form's fields (unique in the document). */
  readonly id = uid("form");
  private readonly messages = new Map<string, string[]>();
  private generalMessage = "";

  /**
   * `root` is the form's element (its fields say which paths they stand for); `changed` draws the form
   * again when a message comes or goes.
   */
  constructor(
    private readonly root: Element,
    private readonly changed: () => void,
  ) {}

  /** The messages at the field (or group of fields) `path`. */
  at(path: string): readonly string[] {
    return this.messages.get(path) ?? [];
  }

  /** The message about the form as a whole ("" for none). */
  get general(): string {
    return this.generalMessage;
  }

  /** Clear the messages of the field under `path` and of the groups that hold it (its value changed). */
  clearField(path: string): void {
    const parts = path.split(".");
    let cleared = false;
    for (let length = parts.length; length > 0; length--)
      cleared = this.messages.delete(parts.slice(0, length).join(".")) || cleared;
    if (cleared) this.changed();
  }

  /** Forget the messages of the fields under `prefix` (the regions were re-indexed). */
  forget(prefix: string): void {
    const under = [...this.messages.keys()].filter((path) => path.startsWith(`${prefix}.`));
    for (const path of under) this.messages.delete(path);
    if (under.length > 0) this.changed();
  }

  /**
   * For the form's `@input` and `@change`: a message about a value goes as soon as the value changes (it
   * may be fixed now, and the next submission says again if not).
   */
  readonly onInput = (event: Event): void => {
    const control = (event.target as Element | null)?.closest<HTMLElement>("[data-path]");
    if (control?.dataset.path) this.clearField(control.dataset.path);
  };

  clear(): void {
    if (this.messages.size === 0 && this.generalMessage === "") return;
    this.messages.clear();
    this.generalMessage = "";
    this.changed();
  }

  /** Show a 422's problems at their fields; the first field in error receives the focus. */
  showProblems(problems: readonly ValidationProblem[]): void {
    this.messages.clear();
    const paths = [...this.root.querySelectorAll<HTMLElement>("[data-error-path]")].map((e) => e.dataset.errorPath);
    const placed = placeProblems(
      problems,
      paths.filter((p): p is string => p !== undefined),
    );
    for (const [path, messages] of placed.byField) this.messages.set(path, messages);
    this.generalMessage = placed.general.join(" · ");
    this.changed();
    this.focus([...placed.byField.keys()]);
  }

  /** Show one message at one field (a client-side problem, e.g. JSON that does not parse). */
  showField(path: string, message: string): void {
    if (this.root.querySelector(`[data-error-path="${CSS.escape(path)}"]`) === null) {
      this.showGeneral(message);
      return;
    }
    this.messages.set(path, [message]);
    this.changed();
    this.focus([path]);
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
    this.generalMessage = message;
    this.changed();
  }

  /** Give the focus to the control of the first of `paths` that has one. */
  private focus(paths: readonly string[]): void {
    for (const path of paths) {
      const control = this.root.querySelector<HTMLElement>(`[data-path="${CSS.escape(path)}"]`);
      if (control) {
        control.focus();
        return;
      }
    }
  }
}

/** The text of a field's messages: the first few, and how many more. */
function messageText(messages: readonly string[]): string {
  const shown = messages.slice(0, MAX_MESSAGES);
  const more = messages.length - shown.length;
  return shown.join(" · ") + (more > 0 ? ` (+${more} more)` : "");
}

/** The place of the messages about a field or a group of fields (`path`), hidden while there are none. */
export function errorSlot(errors: FormErrors, path: string, id?: string): TemplateResult {
  const messages = errors.at(path);
  return html`<p class="field-error" id=${ifDefined(id)} data-error-path=${path} ?hidden=${messages.length === 0}>
    ${messageText(messages)}
  </p>`;
}

/** The form's message as a whole, announced to screen readers. */
export function generalError(errors: FormErrors): TemplateResult {
  return html`<div class="form-error" role="alert" ?hidden=${errors.general === ""}>${errors.general}</div>`;
}

export interface FieldOptions {
  label: string;
  /** the request field it edits, e.g. "policy.temperature": its 422s appear at it (with `errors`) */
  path?: string;
  errors?: FormErrors;
  hint?: string;
  class?: string;
  /** a word of the Horde papers: the label explains it in its tooltip */
  term?: Term;
  /** the control's id (needed without `errors` and `path`, which make one) */
  id?: string;
  hidden?: boolean;
}

/** What a field gives its control: its id, what describes it (hint, message), whether it is in error. */
export interface Control {
  id: string;
  describedBy: string | undefined;
  invalid: "true" | undefined;
  /** the path it edits (`data-path`): typing in it clears its messages, a 422 gives it the focus */
  path: string | undefined;
}

/** A label, its control, an optional hint and the place for the field's error message. */
export function field(o: FieldOptions, control: (c: Control) => unknown): TemplateResult {
  const id = o.id ?? (o.errors && o.path !== undefined ? `${o.errors.id}-${o.path}` : undefined);
  if (id === undefined) throw new Error(`field ${o.label}: give it an id, or errors and a path`);
  const hintId = o.hint ? `${id}-hint` : undefined;
  const errorId = o.errors && o.path !== undefined ? `${id}-error` : undefined;
  const invalid = errorId !== undefined && o.errors !== undefined && o.errors.at(o.path ?? "").length > 0;
  const c: Control = {
    id,
    describedBy: [hintId, errorId].filter(Boolean).join(" ") || undefined,
    invalid: invalid ? "true" : undefined,
    path: errorId !== undefined ? o.path : undefined,
  };
  return html`<div class="field ${o.class ?? ""}" ?hidden=${o.hidden ?? false}>
    ${termLabel(o.label, id, o.term)} ${control(c)}
    ${hintId ? html`<p class="hint" id=${hintId}>${o.hint}</p>` : nothing}
    ${errorId && o.errors && o.path !== undefined ? errorSlot(o.errors, o.path, errorId) : nothing}
  </div>`;
}

/** A label; given a term, dotted and explained in its tooltip. */
export function termLabel(label: string, forId: string, term?: Term): TemplateResult {
  return term
    ? html`<label for=${forId} title=${tip(term)}><span class="term">${label}</span></label>`
    : html`<label for=${forId}>${label}</label>`;
}

export interface InputOptions<E extends Element = HTMLInputElement> {
  name?: string;
  ref?: Ref<E>;
  /** the value it starts with (later values are written through the ref) */
  value?: string | number | null;
  /** or the value it shows at every render (a form that keeps what is typed in its own state) */
  current?: string;
  placeholder?: string;
  /** `data-field`, which the browser tests find it by */
  field?: string;
  /** a <datalist> of suggestions */
  list?: string;
  onInput?: (event: Event) => void;
  onChange?: (event: Event) => void;
  /** shown but not editable (a number input: the hint says why) */
  disabled?: boolean;
}

/**
 * A number input that never blocks submission: no min/max/step checks in the browser, since the
 * server's 422 names the field and says why.
 */
export function numberInput(c: Control, o: InputOptions): TemplateResult {
  return html`<input
    type="number"
    step="any"
    inputmode="decimal"
    id=${c.id}
    name=${ifDefined(o.name)}
    value=${o.value ?? ""}
    placeholder=${ifDefined(o.placeholder)}
    aria-describedby=${ifDefined(c.describedBy)}
    aria-invalid=${ifDefined(c.invalid)}
    data-path=${ifDefined(c.path)}
    data-field=${ifDefined(o.field)}
    .value=${o.current === undefined ? noChange : live(o.current)}
    ?disabled=${o.disabled ?? false}
    @input=${o.onInput}
    @change=${o.onChange}
    ${ref(o.ref)}
  />`;
}

export function textInput(c: Control, o: InputOptions): TemplateResult {
  return html`<input
    type="text"
    autocomplete="off"
    spellcheck="false"
    id=${c.id}
    name=${ifDefined(o.name)}
    value=${o.value ?? ""}
    placeholder=${ifDefined(o.placeholder)}
    list=${ifDefined(o.list)}
    aria-describedby=${ifDefined(c.describedBy)}
    aria-invalid=${ifDefined(c.invalid)}
    data-path=${ifDefined(c.path)}
    data-field=${ifDefined(o.field)}
    .value=${o.current === undefined ? noChange : live(o.current)}
    @input=${o.onInput}
    @change=${o.onChange}
    ${ref(o.ref)}
  />`;
}

/** A <textarea> of `rows` lines. */
export function textArea(c: Control, o: InputOptions<HTMLTextAreaElement>, rows: number): TemplateResult {
  return html`<textarea
    rows=${rows}
    spellcheck="false"
    id=${c.id}
    name=${ifDefined(o.name)}
    aria-describedby=${ifDefined(c.describedBy)}
    aria-invalid=${ifDefined(c.invalid)}
    data-path=${ifDefined(c.path)}
    data-field=${ifDefined(o.field)}
    .value=${o.current === undefined ? noChange : live(o.current)}
    @input=${o.onInput}
    ${ref(o.ref)}
  ></textarea>`;
}

/** A <select> of `options` (templates of <option>s). */
export function select(c: Control, o: InputOptions<HTMLSelectElement>, options: unknown): TemplateResult {
  return html`<select
    id=${c.id}
    name=${ifDefined(o.name)}
    aria-describedby=${ifDefined(c.describedBy)}
    aria-invalid=${ifDefined(c.invalid)}
    data-path=${ifDefined(c.path)}
    data-field=${ifDefined(o.field)}
    .value=${o.current === undefined ? noChange : live(o.current)}
    @change=${o.onChange}
    ${ref(o.ref)}
  >
    ${options}
  </select>`;
}

export const numberField = (f: FieldOptions, o: InputOptions = {}): TemplateResult =>
  field(f, (c) => numberInput(c, o));
export const textField = (f: FieldOptions, o: InputOptions = {}): TemplateResult => field(f, (c) => textInput(c, o));
export const selectField = (f: FieldOptions, o: InputOptions<HTMLSelectElement>, options: unknown): TemplateResult =>
  field(f, (c) => select(c, o, options));

/** A checkbox with its label after it. */
export function checkbox(label: string, id: string, o: InputOptions & { checked?: boolean } = {}): TemplateResult {
  return html`<div class="field checkbox">
    <input type="checkbox" id=${id} name=${ifDefined(o.name)} ?checked=${o.checked ?? false} ${ref(o.ref)} /><label
      for=${id}
      >${label}</label
    >
  </div>`;
}

/**
 * The one entry of a list with nothing to choose yet: the catalogue is still on its way, or the server
 * has none. Its value is empty, so a form that launches from the list waits (its button is disabled).
 */
export function nothingToChoose(loaded: boolean, what: string): TemplateResult {
  return html`<option value="" disabled selected>
    ${loaded ? `no ${what} on the server` : `loading the ${what}…`}
  </option>`;
}

/**
 * For a form that keeps what is typed in its own state: the control shows `target[key]`, and what is typed
 * or chosen goes there at once (then `then`, e.g. a redraw where the choice shows other fields).
 */
export function bound<K extends string>(
  target: Record<K, string>,
  key: K,
  then?: () => void,
): Pick<InputOptions, "current" | "onInput" | "onChange"> {
  const take = (event: Event) => {
    target[key] = (event.target as HTMLInputElement).value;
    then?.();
  };
  return { current: target[key], onInput: take, onChange: take };
}

/** The value of an input or select behind `r` ("" before it is drawn). */
export function valueOf(r: Ref<HTMLInputElement | HTMLSelectElement | HTMLTextAreaElement>): string {
  return r.value?.value ?? "";
}

/** Write `value` into the input behind `r` (a form filling itself). */
export function setValue(r: Ref<HTMLInputElement | HTMLSelectElement | HTMLTextAreaElement>, value: string): void {
  if (r.value) r.value.value = value;
}
