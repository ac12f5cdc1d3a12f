/**
 * The guided tour for a class: a few steps that point at the live view, the charts, the table and the
 * run's controls and say what to watch. It offers itself once per browser (remembered in localStorage as
 * soon as it opens): the first time a classroom run is selected, or a run is selected in classroom mode,
 * never before there is a run to show; "Take the tour" starts it on demand. A stop whose panel shows
 * nothing yet is left out, and the dialog is never laid over the upper half of the part it explains
 * (the live view's value-map legend stands at the world's top): below or above it, the page scrolled to
 * make room, else beside it (lib/tour-place.ts), placed again when the part changes size.
 */
import type { AppStore } from "../app/state";
import { tourPlacement } from "../lib/tour-place";
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
  let stops: Stop[] = [];
  let lit: Element | null = null;

  // The dialog beside its part (lib/tour-place.ts): `scrolling` lets the page scroll to make room (a new stop,
  // the part resized); without it, the dialog follows the part where the page stands (the reader scrolled).
  const position = (scrolling: boolean) => {
    if (!lit) return;
    const root = document.documentElement;
    const box = lit.getBoundingClientRect();
    const maxScroll = Math.max(0, root.scrollHeight - window.innerHeight);
    const placed = tourPlacement(
      { top: box.top + window.scrollY, height: box.height, left: box.left, right: box.right },
      { width: element.offsetWidth, height: element.offsetHeight },
      {
        width: root.clientWidth,
        height: window.innerHeight,
        minScroll: scrolling ? 0 : window.scrollY,
        maxScroll: scrolling ? maxScroll : window.scrollY,
      },
    );
    if (placed.scroll !== window.scrollY) window.scrollTo(0, placed.scroll);
    element.style.left = `${placed.left}px`;
    element.style.top = `${placed.top}px`;
  };

  // A part that grows or shrinks while it is explained (charts arriving) has the dialog placed again.
  const resized = new ResizeObserver(() => at >= 0 && position(true));

  const place = () => {
    const stop = stops[at];
    const target = stop ? document.querySelector(stop.target) : null;
    if (!stop || !target) return;
    lit?.classList.remove("tour-target");
    lit = target;
    target.classList.add("tour-target");
    resized.disconnect();
    resized.observe(target);
    setText(title, stop.title);
    setText(text, stop.text);
    setText(count, `${at + 1} of ${stops.length}`);
    back.disabled = at === 0;
    setText(next, at === stops.length - 1 ? "Done" : "Next");
    position(true);
  };
  const finish = () => {
    at = -1;
    element.hidden = true;
    resized.disconnect();
    lit?.classList.remove("tour-target");
    lit = null;
  };

  const start = () => {
    store.update({ tab: "live" });
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
  window.addEventListener("resize", () => at >= 0 && position(true));
  window.addEventListener("scroll", () => at >= 0 && position(false), { passive: true });

  // First time a classroom run is shown, or a run in classroom mode: the tour offers itself, once the
  // panels have drawn the run (the store's subscribers run before the browser lays them out).
  store.subscribe(
    ({ run, classroom }) => {
      const classroomRun = run?.spec.name?.startsWith("classroom") ?? false;
      if (at < 0 && run !== null && !remembered() && (classroomRun || classroom))
        requestAnimationFrame(() => at < 0 && !remembered() && start());
    },
    ["run", "classroom"],
  );
  return { element, start };
}
