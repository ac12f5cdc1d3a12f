/**
 * "Press twice to confirm" for the actions that throw something away (a run, a demon, a library world):
 * the first press arms the button and changes its words, a second press within `ms` does the action, and
 * an armed button turns back by itself (a paused run sends no messages to re-render it).
 */
import { h } from "./dom";

/** How long an armed button waits for the second press. */
export const CONFIRM_MS = 4000;

export interface ConfirmOptions {
  /** the button's words, armed or not (the owner may say more, e.g. "Removing…" while it works) */
  text: (armed: boolean) => string;
  /** its accessible name, armed or not (default: the text) */
  label?: (armed: boolean) => string;
  /** the action, on the second press */
  onConfirm: () => void;
  /** told when the button arms or turns back (to re-render what depends on it) */
  onChange?: () => void;
  class?: string;
  ms?: number;
}

export interface ConfirmButton {
  readonly button: HTMLButtonElement;
  /** true while a press would do the action */
  armed(): boolean;
  /** Turn back without acting (the thing it would act on changed). */
  disarm(): void;
  /** Write the words and the name again (after the owner's state changed). */
  refresh(): void;
}

export function confirmButton(options: ConfirmOptions): ConfirmButton {
  const ms = options.ms ?? CONFIRM_MS;
  const button = h("button", { type: "button", class: options.class ?? "danger" });
  let timer: ReturnType<typeof setTimeout> | undefined;
  let isArmed = false;

  const refresh = () => {
    const text = options.text(isArmed);
    if (button.textContent !== text) button.textContent = text;
    button.setAttribute("aria-label", (options.label ?? options.text)(isArmed));
  };
  const set = (next: boolean) => {
    clearTimeout(timer);
    timer = undefined;
    if (next) timer = setTimeout(() => set(false), ms);
    if (next === isArmed) return;
    isArmed = next;
    refresh();
    options.onChange?.();
  };
  button.addEventListener("click", () => {
    if (button.disabled) return;
    if (!isArmed) {
      set(true);
      return;
    }
    set(false);
    options.onConfirm();
  });
  refresh();
  return { button, armed: () => isArmed, disarm: () => set(false), refresh };
}
