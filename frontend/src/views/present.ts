/**
 * Present mode, for a projector: the selected run's live view and charts fill the screen, everything else is
 * hidden (styles.css, `html.present`). A "Present" button turns it on (the Live tab's toolbar, a Class tab
 * card); Escape or the "Exit present mode" button turns it off.
 */
import { html, render } from "lit-html";
import type { AppStore } from "../app/state";

/** The one element a template draws (views here are lit-html templates, mounted into an element of their own). */
function element<T extends HTMLElement>(template: ReturnType<typeof html>): T {
  const holder = document.createElement("div");
  render(template, holder);
  return holder.firstElementChild as T;
}

/** The button that presents the selected run. */
export function presentButton(store: AppStore): HTMLButtonElement {
  const button = element<HTMLButtonElement>(
    html`<button
      type="button"
      title="The live view and the charts of the selected run, large, for a projector (Escape leaves)"
      @click=${() => store.update({ present: true, tab: "live" })}
    >
      Present
    </button>`,
  );
  store.subscribe(({ selectedRunId }) => (button.disabled = selectedRunId === null), ["selectedRunId"]);
  button.disabled = store.state.selectedRunId === null;
  return button;
}

/** Keep the page's present class current; returns the button that leaves present mode (shown only then). */
export function keepPresentMode(store: AppStore): HTMLElement {
  const leave = element<HTMLButtonElement>(
    html`<button type="button" class="present-exit" @click=${() => store.update({ present: false })}>
      Exit present mode (Esc)
    </button>`,
  );
  const apply = () => {
    const on = store.state.present && store.state.selectedRunId !== null;
    document.documentElement.classList.toggle("present", on);
    leave.hidden = !on;
  };
  store.subscribe(apply, ["present", "selectedRunId"]);
  document.addEventListener("keydown", (event) => {
    if (event.key === "Escape" && store.state.present) store.update({ present: false });
  });
  apply();
  return leave;
}
