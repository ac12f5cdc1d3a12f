/**
 * The guided tour for a class: a few steps that point at the live view, the charts, the table and the
 * run's controls and say what to watch. It starts by itself the first time a classroom run is shown (or
 * classroom mode is switched on), never again once finished or dismissed (remembered in this browser);
 * "Take the tour" starts it on demand.
 */
import type { AppStore } from "../app/state";
import { h, setText } from "../ui/dom";

const DONE_KEY = "horde-lab-tour-done";

interface Stop {
  target: string;
  title: string;
  text: string;
}

export const STOPS: Stop[] = [
  {
    target: ".viser-panel",
    title: "The world",
    text: "The agent (the white disc) wanders at random. Its trail shows this episode; the labels beside it are the demons' predictions where it stands now.",
  },
  {
    target: ".charts-panel",
    title: "One chart per demon",
    text: "Each demon's prediction where the agent stands, step by step, on its own scale. Press Evaluate in the table: at that step a ring shows the demon's prediction from the start and a dark dot the true answer from the same place. Evaluate again later and watch the ring close in on the dot.",
  },
  {
    target: ".demons-panel",
    title: "The demons",
    text: "Each row is one question about the future, all learned at once from the same random walk. RUPEE falls as a demon's answer gets as good as its features allow.",
  },
  {
    target: ".runs-panel",
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

export function tour(store: AppStore): Tour {
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
  let lit: Element | null = null;

  const place = () => {
    const stop = STOPS[at];
    if (!stop) return;
    const target = document.querySelector(stop.target);
    lit?.classList.remove("tour-target");
    lit = target;
    target?.classList.add("tour-target");
    target?.scrollIntoView({ block: "center", behavior: "auto" });
    setText(title, stop.title);
    setText(text, stop.text);
    setText(count, `${at + 1} of ${STOPS.length}`);
    back.disabled = at === 0;
    setText(next, at === STOPS.length - 1 ? "Done" : "Next");
    const box = target?.getBoundingClientRect();
    // Beside the part it explains, inside the window; below it when there is room, else above.
    const width = Math.min(element.offsetWidth || 360, window.innerWidth - 16);
    const left = Math.max(8, Math.min((box?.left ?? 8) + 16, window.innerWidth - width - 8));
    const height = element.offsetHeight || 180;
    const below = (box?.bottom ?? 0) + 8;
    const top = below + height < window.innerHeight ? below : Math.max(8, (box?.top ?? 0) - height - 8);
    element.style.left = `${left}px`;
    element.style.top = `${Math.min(top, window.innerHeight - height - 8)}px`;
  };

  const finish = () => {
    at = -1;
    element.hidden = true;
    lit?.classList.remove("tour-target");
    lit = null;
    remember();
  };

  const start = () => {
    store.update({ tab: "live" });
    at = 0;
    element.hidden = false;
    place();
    next.focus();
  };

  next.addEventListener("click", () => {
    if (at >= STOPS.length - 1) finish();
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

  // First time a classroom run is shown, or classroom mode is switched on: the tour offers itself.
  store.subscribe(
    ({ run, classroom }) => {
      const classroomRun = run?.spec.name?.startsWith("classroom") ?? false;
      if (at < 0 && !remembered() && (classroomRun || classroom)) start();
    },
    ["run", "classroom"],
  );
  return { element, start };
}
