/**
 * The Live tab's switches: classroom mode (every demon charted, one small chart each, and the guided
 * tour on offer) and the tour itself.
 */
import { type App, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { h } from "../ui/dom";

const CLASSROOM_KEY = "horde-lab-classroom";

export function liveToolbar(app: App, scope: Scope, startTour: () => void): HTMLElement {
  const classroom = h(
    "button",
    {
      type: "button",
      "aria-pressed": "false",
      title: "Chart every demon, each on its own scale with its truth, for a class to follow",
    },
    "Classroom mode",
  );
  const set = (on: boolean) => {
    app.ui.update({ classroom: on });
    try {
      localStorage.setItem(CLASSROOM_KEY, on ? "1" : "");
    } catch {
      // storage disabled: the switch still works for this page
    }
  };
  classroom.addEventListener("click", () => set(!state(app).classroom));
  watchState(app, scope, ["classroom"], ({ classroom: on }) => classroom.setAttribute("aria-pressed", String(on)));
  let stored = false;
  try {
    stored = localStorage.getItem(CLASSROOM_KEY) === "1";
  } catch {
    // see above
  }
  set(stored);
  const tour = h("button", { type: "button", onclick: startTour }, "Take the tour");
  return h("div", { class: "live-toolbar", role: "group", "aria-label": "Live view options" }, classroom, tour);
}
