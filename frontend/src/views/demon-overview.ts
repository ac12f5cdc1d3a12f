/**
 * An overview of every demon's prediction at once, for Hordes too large to chart: one cell per demon (in
 * the run's order), blue below zero and orange above, on a log scale so that probabilities and step
 * counts both show. Hover names a cell's demon and its prediction; a click charts it (or stops).
 */
import { toggleCharted } from "../app/actions";
import { type App, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { overviewLevels } from "../lib/demons";
import { formatNumber } from "../lib/format";
import { h, section, setText } from "../ui/dom";

/** Shown once a run has more demons than this (fewer are all charted). */
export const OVERVIEW_FROM = 12;
const REDRAW_MS = 250;

function colourOf(level: number): string {
  if (Number.isNaN(level)) return "#9ca3af"; // no prediction (diverged): grey
  const t = Math.min(1, Math.abs(level));
  // From white to Okabe-Ito blue (negative) or vermilion (positive).
  const [r, g, b] = level < 0 ? [0, 114, 178] : [213, 94, 0];
  const mix = (c: number) => Math.round(255 + (c - 255) * t);
  return `rgb(${mix(r)}, ${mix(g)}, ${mix(b)})`;
}

export function demonOverview(app: App, scope: Scope): HTMLElement {
  const canvas = h("canvas", { role: "img", "aria-label": "Every demon's prediction as a coloured cell" });
  const readout = h(
    "p",
    { class: "hint", "aria-live": "polite" },
    "Hover over a cell to see its demon; click to chart it.",
  );
  const element = section(
    { class: "panel overview", id: "overview-title", title: "All predictions", hidden: true },
    readout,
    canvas,
  );
  let columns = 1;
  let cell = 8;

  const draw = () => {
    const { demons, live } = state(app);
    element.hidden = demons.length <= OVERVIEW_FROM || state(app).tab !== "live";
    if (element.hidden) return;
    const width = Math.max(100, canvas.clientWidth);
    cell = Math.max(4, Math.min(24, Math.floor(Math.sqrt((width * 240) / demons.length))));
    columns = Math.max(1, Math.floor(width / cell));
    const rows = Math.ceil(demons.length / columns);
    canvas.width = columns * cell;
    canvas.height = rows * cell;
    canvas.style.height = `${(rows * cell * width) / canvas.width}px`;
    const context = canvas.getContext("2d");
    if (!context) return;
    const levels = overviewLevels(demons.map((d) => (live ? live.predictions[d.name] : d.prediction)));
    levels.forEach((level, i) => {
      context.fillStyle = colourOf(level);
      context.fillRect(
        (i % columns) * cell,
        Math.floor(i / columns) * cell,
        cell - (cell > 6 ? 1 : 0),
        cell - (cell > 6 ? 1 : 0),
      );
    });
  };

  const demonAt = (event: MouseEvent) => {
    const box = canvas.getBoundingClientRect();
    const scale = canvas.width / box.width;
    const i =
      Math.floor(((event.clientY - box.top) * scale) / cell) * columns +
      Math.floor(((event.clientX - box.left) * scale) / cell);
    return state(app).demons[i];
  };
  canvas.addEventListener("mousemove", (event) => {
    const demon = demonAt(event);
    if (!demon) return;
    const value = state(app).live?.predictions[demon.name] ?? demon.prediction;
    setText(
      readout,
      `${demon.name}: ${formatNumber(value)}${state(app).charted.includes(demon.name) ? " (charted)" : ""}`,
    );
  });
  canvas.addEventListener("click", (event) => {
    const demon = demonAt(event);
    if (demon) toggleCharted(app, demon.name, !state(app).charted.includes(demon.name));
  });

  watchState(app, scope, ["demons", "tab"], draw);
  window.setInterval(() => {
    if (!document.hidden) draw();
  }, REDRAW_MS);
  return element;
}
