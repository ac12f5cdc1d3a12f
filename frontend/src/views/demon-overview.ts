/**
 * An overview of every demon's prediction at once, for Hordes too large to chart: one cell per demon (in
 * the run's order), blue below zero and orange above, on a log scale so that probabilities and step
 * counts both show. Hover names a cell's demon and its prediction; a click charts it (or stops).
 */
import { html } from "lit-html";
import { createRef, ref } from "lit-html/directives/ref.js";
import { toggleCharted } from "../app/actions";
import { type App, state, watchState } from "../app/app";
import { mount } from "../app/view";
import { overviewLevels } from "../lib/demons";
import { formatNumber } from "../lib/format";
import { heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";

/** Shown once a run has more demons than this (fewer are all charted). */
export const OVERVIEW_FROM = 12;
const REDRAW_MS = 250;
const HINT = "Hover over a cell to see its demon; click to chart it.";

function colourOf(level: number): string {
  if (Number.isNaN(level)) return "#9ca3af"; // no prediction (diverged): grey
  const t = Math.min(1, Math.abs(level));
  // From white to Okabe-Ito blue (negative) or vermilion (positive).
  const [r, g, b] = level < 0 ? [0, 114, 178] : [213, 94, 0];
  const mix = (c: number) => Math.round(255 + (c - 255) * t);
  return `rgb(${mix(r)}, ${mix(g)}, ${mix(b)})`;
}

/** How the cells are laid out on the canvas. */
interface Grid {
  columns: number;
  cell: number;
}

export function demonOverview(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel overview" aria-labelledby="overview-title" hidden></section>`);
  const canvas = createRef<HTMLCanvasElement>();
  const grid: Grid = { columns: 1, cell: 8 };
  let readout = HINT;
  const demonAt = (event: MouseEvent) => {
    const box = (event.target as HTMLCanvasElement).getBoundingClientRect();
    const scale = (canvas.value?.width ?? box.width) / box.width;
    const row = Math.floor(((event.clientY - box.top) * scale) / grid.cell);
    return state(app).demons[row * grid.columns + Math.floor(((event.clientX - box.left) * scale) / grid.cell)];
  };
  const onMove = (event: MouseEvent) => {
    const demon = demonAt(event);
    if (!demon) return;
    const { live, charted } = state(app);
    const value = live?.predictions[demon.name] ?? demon.prediction;
    readout = `${demon.name}: ${formatNumber(value)}${charted.includes(demon.name) ? " (charted)" : ""}`;
    redraw();
  };
  const onClick = (event: MouseEvent) => {
    const demon = demonAt(event);
    if (demon) toggleCharted(app, demon.name, !app.ui.state.charted.includes(demon.name));
  };
  const redraw = mount(app, scope, element, ["demons", "tab"], ({ demons, tab }) => {
    element.hidden = demons.length <= OVERVIEW_FROM || tab !== "live";
    return html`${heading({ id: "overview-title", title: "All predictions" })}
      <p class="hint" aria-live="polite">${readout}</p>
      <canvas
        role="img"
        aria-label="Every demon's prediction as a coloured cell"
        ${ref(canvas)}
        @mousemove=${onMove}
        @click=${onClick}
      ></canvas>`;
  });
  // The predictions change 30 times a second: the cells are painted four times a second, while shown.
  const paint = () => {
    if (!element.hidden && !document.hidden && canvas.value) draw(canvas.value, grid, app);
  };
  scope.every(REDRAW_MS, paint);
  watchState(app, scope, ["demons", "tab"], paint); // at once when they change, after the section is drawn
  return element;
}

function draw(canvas: HTMLCanvasElement, grid: Grid, app: App): void {
  const { demons, live } = state(app);
  const width = Math.max(100, canvas.clientWidth);
  grid.cell = Math.max(4, Math.min(24, Math.floor(Math.sqrt((width * 240) / demons.length))));
  grid.columns = Math.max(1, Math.floor(width / grid.cell));
  const { cell, columns } = grid;
  const rows = Math.ceil(demons.length / columns);
  canvas.width = columns * cell;
  canvas.height = rows * cell;
  canvas.style.height = `${(rows * cell * width) / canvas.width}px`;
  const context = canvas.getContext("2d");
  if (!context) return;
  const levels = overviewLevels(demons.map((d) => (live ? live.predictions[d.name] : d.prediction)));
  const size = cell - (cell > 6 ? 1 : 0);
  levels.forEach((level, i) => {
    context.fillStyle = colourOf(level);
    context.fillRect((i % columns) * cell, Math.floor(i / columns) * cell, size, size);
  });
}
