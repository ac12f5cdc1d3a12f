/**
 * "Press twice to confirm" for the actions that throw something away (a run, a demon, a library world):
 * the first press arms the button and changes its words, a second press within `ms` does the action, and
 * an armed button turns back by itself (a paused run sends no messages to re-render it).
 */
import { type TemplateResult, html } from "lit-html";
import { ifDefined } from "lit-html/directives/if-defined.js";
import type { Scope } from "./scope";

/** How long an armed button waits for the second press. */
export const CONFIRM_MS = 4000;

/** One button's armed state, kept across renders (it outlives the template that draws it). */
export class Confirm {
  private isArmed = false;
  private cancel: () => void = () => {};

  /** `changed` draws the button again when it arms or turns back; its timer goes with `scope`. */
  constructor(
    private readonly scope: Scope,
    private readonly changed: () => void,
    private readonly ms = CONFIRM_MS,
  ) {}

  /** true while a press would do the action */
  get armed(): boolean {
    return this.isArmed;
  }

  /** The first press arms; a second within the wait does `act`. */
  press(act: () => void): void {
    if (!this.isArmed) {
      this.set(true);
      return;
    }
    this.set(false);
    act();
  }

  /** Turn back without acting (the thing it would act on changed). */
  disarm(): void {
    this.set(false);
  }

  private set(next: boolean): void {
    this.cancel();
    this.cancel = next ? this.scope.after(this.ms, () => this.set(false)) : () => {};
    if (next === this.isArmed) return;
    this.isArmed = next;
    this.changed();
  }
}

export interface ConfirmButton {
  /** the button's words, armed or not (the owner may say more, e.g. "Removing…" while it works) */
  text: (armed: boolean) => string;
  /** its accessible name, armed or not (default: the text) */
  label?: (armed: boolean) => string;
  /** the action, on the second press */
  onConfirm: () => void;
  class?: string;
  disabled?: boolean;
  title?: string;
}

/** The button of `confirm`: a press arms it, a second one acts. */
export function confirmButton(confirm: Confirm, o: ConfirmButton): TemplateResult {
  const armed = confirm.armed;
  return html`<button
    type="button"
    class=${o.class ?? "danger"}
    aria-label=${(o.label ?? o.text)(armed)}
    title=${ifDefined(o.title)}
    ?disabled=${o.disabled ?? false}
    @click=${(event: Event) => {
      if (!(event.currentTarget as HTMLButtonElement).disabled) confirm.press(o.onConfirm);
    }}
  >
    ${o.text(armed)}
  </button>`;
}
