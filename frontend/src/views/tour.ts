/**
 * The guided tour for a class: a few steps that point at the live view, the charts, the table and the
 * run's controls and say what to watch. It offers itself once per browser (remembered in localStorage as
 * soon as it opens): the first time a classroom run is selected, or a run is selected in classroom mode,
 * never before there is a run to show; "Take the tour" starts it on demand. A stop whose panel shows
 * nothing yet is left out, and the dialog is never laid over the upper half of the part it explains
 * (the live view's value-map legend stands at the world's top): below or above it, the page scrolled to
 * make room, else beside it (lib/tour-place.ts), placed again when the part changes size.
 */
import { html, render } from "lit-html";
import { type App, watchState } from "../app/app";
import { readFlag, writeFlag } from "../lib/stored";
import { tourPlacement } from "../lib/tour-place";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";

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

export interface Tour {
  element: HTMLElement;
  start: () => void;
}

/** Where the tour is: its stops (those with something to show), the one shown (-1: none), the part lit. */
interface Guide {
  element: HTMLElement;
  stops: Stop[];
  at: number;
  lit: Element | null;
  /** watches the part lit: one that grows or shrinks while it is explained (charts arriving) has the dialog
   * placed again */
  resized: ResizeObserver;
}

export function tour(app: App, scope: Scope): Tour {
  const element = host(
    html`<div class="tour" role="dialog" aria-labelledby="tour-title" aria-describedby="tour-text" hidden></div>`,
  );
  const guide: Guide = {
    element,
    stops: [],
    at: -1,
    lit: null,
    resized: new ResizeObserver(() => guide.at >= 0 && position(guide, true)),
  };
  scope.add(() => guide.resized.disconnect());
  const show = () => {
    draw(guide, () => show());
    place(guide);
  };
  const start = () => {
    app.ui.update({ tab: "live" });
    writeFlag(DONE_KEY, true);
    guide.stops = STOPS.filter((stop) => document.querySelector(`${stop.target} ${stop.content}`) !== null);
    if (guide.stops.length === 0) return;
    guide.at = 0;
    show();
    element.querySelector<HTMLButtonElement>("button.primary")?.focus();
  };
  draw(guide, show);
  scope.listen<KeyboardEvent>(document, "keydown", (event) => {
    if (event.key === "Escape" && guide.at >= 0) finish(guide, show);
  });
  scope.listen(window, "resize", () => guide.at >= 0 && position(guide, true));
  scope.listen(window, "scroll", () => guide.at >= 0 && position(guide, false), { passive: true });
  // First time a classroom run is shown, or a run in classroom mode: the tour offers itself, once the
  // panels have drawn the run (the state's listeners run before the browser lays them out).
  watchState(app, scope, ["run", "classroom"], ({ run, classroom }) => {
    const classroomRun = run?.spec.name?.startsWith("classroom") ?? false;
    if (guide.at < 0 && run !== null && !readFlag(DONE_KEY) && (classroomRun || classroom)) {
      const frame = requestAnimationFrame(() => guide.at < 0 && !readFlag(DONE_KEY) && start());
      scope.add(() => cancelAnimationFrame(frame));
    }
  });
  return { element, start };
}

/** The dialog: the stop's title and words, how far along, and Close, Back and Next (Done at the last). */
function draw(guide: Guide, show: () => void): void {
  const { stops, at } = guide;
  const stop = stops[at];
  guide.element.hidden = stop === undefined;
  const next = () => {
    if (guide.at >= guide.stops.length - 1) finish(guide, show);
    else {
      guide.at += 1;
      show();
    }
  };
  const back = () => {
    guide.at = Math.max(0, guide.at - 1);
    show();
  };
  render(
    html`<h2 id="tour-title">${stop?.title ?? ""}</h2>
      <p id="tour-text">${stop?.text ?? ""}</p>
      <div class="tour-actions">
        <span class="muted">${stop ? `${at + 1} of ${stops.length}` : ""}</span>
        <button type="button" @click=${() => finish(guide, show)}>Close the tour</button>
        <button type="button" ?disabled=${at === 0} @click=${back}>Back</button>
        <button type="button" class="primary" @click=${next}>${at === stops.length - 1 ? "Done" : "Next"}</button>
      </div>`,
    guide.element,
  );
}

function finish(guide: Guide, show: () => void): void {
  guide.at = -1;
  guide.resized.disconnect();
  guide.lit?.classList.remove("tour-target");
  guide.lit = null;
  show();
}

/** Light the stop's part, watch its size, and lay the dialog beside it. */
function place(guide: Guide): void {
  const stop = guide.stops[guide.at];
  const target = stop ? document.querySelector(stop.target) : null;
  if (!stop || !target) return;
  guide.lit?.classList.remove("tour-target");
  guide.lit = target;
  target.classList.add("tour-target");
  guide.resized.disconnect();
  guide.resized.observe(target);
  position(guide, true);
}

/**
 * The dialog beside its part (lib/tour-place.ts): `scrolling` lets the page scroll to make room (a new stop,
 * the part resized); without it, the dialog follows the part where the page stands (the reader scrolled).
 */
function position(guide: Guide, scrolling: boolean): void {
  const { element, lit } = guide;
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
}
