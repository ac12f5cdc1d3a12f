/**
 * The Live tab's switches: classroom mode (every demon charted, one small chart each, and the guided
 * tour on offer), the tour itself, and present mode (views/present.ts).
 */
import { html } from "lit-html";
import type { App } from "../app/app";
import { mount } from "../app/view";
import { readFlag, writeFlag } from "../lib/stored";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { presentButton } from "./present";

const CLASSROOM_KEY = "horde-lab-classroom";

export function liveToolbar(app: App, scope: Scope, startTour: () => void): HTMLElement {
  const element = host(html`<div class="live-toolbar" role="group" aria-label="Live view options"></div>`);
  const set = (on: boolean) => {
    app.ui.update({ classroom: on });
    writeFlag(CLASSROOM_KEY, on);
  };
  set(readFlag(CLASSROOM_KEY));
  mount(
    app,
    scope,
    element,
    ["classroom", "selectedRunId"],
    ({ classroom, selectedRunId }) =>
      html`<button
          type="button"
          aria-pressed=${String(classroom)}
          title="Chart every demon, each on its own scale with its truth, for a class to follow"
          @click=${() => set(!app.ui.state.classroom)}
        >
          Classroom mode
        </button>
        <button type="button" @click=${startTour}>Take the tour</button>
        ${presentButton(app, selectedRunId)}`,
  );
  return element;
}
