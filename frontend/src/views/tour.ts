/**
 * The guided tour for a class: a few steps that point at the live view, the charts, the table and the
 * run's controls and say what to watch. It offers itself once per browser (remembered in localStorage as
 * soon as it opens): the first time a classroom run is selected, or a run is selected in classroom mode,
 * never before there is a run to show; "Take the tour" starts it on demand. A stop whose panel shows
 * nothing yet is left out, and the dialog is never laid over the upper part of the part it explains
 * (the live view's value-map legend stands at the world's top).
 */
import { type App, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { h, setText } from "../ui/dom";

const DONE_KEY = "horde-lab-tour-done";

interface Stop {
  target: string;
  /** what the target holds once it has something to show: without it the stop is left out */
  content: string;
  title: string;
  text: string;
}

export const STOPS: Stop[] = [
  {
    target: ".viser-panel",
    content: "iframe.viser-frame",
    title: "The world",
    text: "The agent (the white disc) wanders at random. Its trail shows this episode; the labels beside it are the demons' predictions where it stands now.",
  },
  {
    target: ".charts-panel",
    content: ".chart",
    title: "One chart per demon",
    text: "Each demon's prediction where the agent stands, step by step, on its own scale. Press Evaluate in the table: at that step a ring shows the demon's prediction from the start and a dark dot the true answer from the same place. Evaluate again later and watch the ring close in on the dot.",
  },
  {
    target: ".demons-panel",
    content: "tr[data-demon]",
    title: "The demons",
    text: "Each row is one question about the future, all learned at once from the same random walk. RUPEE falls as a demon's answer gets as good as its features allow.",
  },
  {
    target: ".runs-panel",
    content: "li.run-item",
    title: "Speed and control",
    text: "Slow the run to follow each step, or go to full speed to learn quickly. Space starts and pauses, s steps, ? shows every word and key.",
  },
];

function remembered(): boolean {
  try {
    return localStorage.getItem(DONE_KEY) === "1";
  } catch {
    return false;
  }
}

function remember(): void {
  try {
    localStorage.setItem(DONE_KEY, "1");
  } catch {
    // storage disabled: the tour may come back on the next visit
  }
}

export interface Tour {
  element: HTMLElement;
  start: () => void;
}

export function tour(app: App, scope: Scope): Tour {
  const title = h("h2", { id: "tour-title" });
  const text = h("p", { id: "tour-text" });
  const count = h("span", { class: "muted" });
  const back = h("button", { type: "button" }, "Back");
  const next = h("button", { type: "button", class: "primary" }, "Next");
  const skip = h("button", { type: "button" }, "Close the tour");
  const element = h(
    "div",
    {
      class: "tour",
      role: "dialog",
      "aria-labelledby": "tour-title",
      "aria-describedby": "tour-text",
      hidden: true,
    },
    title,
    text,
    h("div", { class: "tour-actions" }, count, skip, back, next),
  );
  let at = -1;
  let stops: Stop[] = [];
  let lit: Element | null = null;

  const place = () => {
    const stop = stops[at];
    const target = stop ? document.querySelector(stop.target) : null;
    if (!stop || !target) return;
    lit?.classList.remove("tour-target");
    lit = target;
    target.classList.add("tour-target");
    setText(title, stop.title);
    setText(text, stop.text);
    setText(count, `${at + 1} of ${stops.length}`);
    back.disabled = at === 0;
    setText(next, at === stops.length - 1 ? "Done" : "Next");
    // A part taller than the window is shown from its top (where the live view's legend is).
    const tall = target.getBoundingClientRect().height > window.innerHeight;
    target.scrollIntoView({ block: tall ? "start" : "center", behavior: "auto" });
    const box = target.getBoundingClientRect();
    const width = Math.min(element.offsetWidth || 360, window.innerWidth - 16);
    const height = element.offsetHeight || 180;
    let left = Math.max(8, Math.min(box.left + 16, window.innerWidth - width - 8));
    // Below the part when there is room, else above it, else beside it, else over its lowest part: never over
    // its top.
    const below = box.bottom + 8;
    const above = box.top - height - 8;
    const beside =
      box.left - width - 8 >= 8
        ? box.left - width - 8
        : box.right + width + 8 <= window.innerWidth
          ? box.right + 8
          : null;
    let top: number;
    if (below + height <= window.innerHeight - 8) top = below;
    else if (above >= 8) top = above;
    else if (beside !== null) {
      left = beside;
      top = Math.max(8, Math.min(box.top, window.innerHeight - height - 8));
    } else top = Math.max(8, Math.min(box.bottom, window.innerHeight) - height - 8);
    element.style.left = `${left}px`;
    element.style.top = `${top}px`;
  };

  const finish = () => {
    at = -1;
    element.hidden = true;
    lit?.classList.remove("tour-target");
    lit = null;
  };

  const start = () => {
    app.ui.update({ tab: "live" });
    remember();
    stops = STOPS.filter((stop) => document.querySelector(`${stop.target} ${stop.content}`) !== null);
    if (stops.length === 0) return;
    at = 0;
    element.hidden = false;
    place();
    next.focus();
  };

  next.addEventListener("click", () => {
    if (at >= stops.length - 1) finish();
    else {
      at += 1;
      place();
    }
  });
  back.addEventListener("click", () => {
    at = Math.max(0, at - 1);
    place();
  });
  skip.addEventListener("click", finish);
  document.addEventListener("keydown", (event) => {
    if (event.key === "Escape" && at >= 0) finish();
  });
  window.addEventListener("resize", () => at >= 0 && place());

  // First time a classroom run is shown, or a run in classroom mode: the tour offers itself, once the
  // panels have drawn the run (the store's subscribers run before the browser lays them out).
  watchState(app, scope, ["run", "classroom"], ({ run, classroom }) => {
    const classroomRun = run?.spec.name?.startsWith("classroom") ?? false;
    if (at < 0 && run !== null && !remembered() && (classroomRun || classroom))
      requestAnimationFrame(() => at < 0 && !remembered() && start());
  });
  return { element, start };
}
