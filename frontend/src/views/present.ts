/**
 * Present mode, for a projector: the selected run's live view and charts fill the screen, everything else is
 * hidden (styles.css, `html.present`). A "Present" button turns it on (the Live tab's toolbar, a Class tab
 * card); Escape or the "Exit present mode" button turns it off.
 */
import { html } from "lit-html";
import type { App } from "../app/app";
import { mount } from "../app/view";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";

/** The button that presents the selected run (a template, for the Live tab's toolbar). */
export function presentButton(app: App, selectedRunId: string | null) {
  return html`<button
    type="button"
    title="The live view and the charts of the selected run, large, for a projector (Escape leaves)"
    ?disabled=${selectedRunId === null}
    @click=${() => app.ui.update({ present: true, tab: "live" })}
  >
    Present
  </button>`;
}

/**
 * Keep the page's present class current, until `scope` goes; returns the button that leaves present mode
 * (shown only then).
 */
export function presentMode(app: App, scope: Scope): HTMLElement {
  const element = host(html`<div class="present-bar"></div>`);
  const root = document.documentElement;
  scope.add(() => root.classList.remove("present"));
  scope.listen<KeyboardEvent>(document, "keydown", (event) => {
    if (event.key === "Escape" && app.ui.state.present) app.ui.update({ present: false });
  });
  mount(app, scope, element, ["present", "selectedRunId"], ({ present, selectedRunId }) => {
    const on = present && selectedRunId !== null;
    root.classList.toggle("present", on);
    return html`<button
      type="button"
      class="present-exit"
      ?hidden=${!on}
      @click=${() => app.ui.update({ present: false })}
    >
      Exit present mode (Esc)
    </button>`;
  });
  return element;
}
