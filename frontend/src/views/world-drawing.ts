/**
 * The live drawing of a world (SVG, y up): the grid of its steps, its regions coloured by kind with
 * their names, and the start point or rectangle. Redrawn from the form's current values on every edit.
 *
 * Given `onEdit`, it is also drawn on by hand: a drag on empty ground draws a new region (of the kind
 * `newKind()` names), a drag on a region moves it, a drag on a corner handle resizes it, a click on
 * empty ground sets the start; all snapped to the step grid. `onEdit(world, false)` follows the drag,
 * `onEdit(world, true)` ends it (the editor then updates its form and its undo history).
 */
import { html, nothing, render, svg } from "lit-html";
import type { Region, WorldSpec } from "../api/types";
import { gridLines, regionFills } from "../lib/world";
import { type Corner, type Rect, moveRect, newRegion, rectFrom, resizeRect, startAt } from "../lib/world-edit";
import { host } from "../ui/html";

const CORNERS: Corner[] = ["x0y0", "x1y0", "x0y1", "x1y1"];

type Drag =
  | { mode: "new"; from: [number, number]; moved: boolean }
  | { mode: "move"; index: number; from: [number, number]; rect: Rect; moved: boolean }
  | { mode: "resize"; index: number; corner: Corner; rect: Rect; moved: boolean };

export interface DrawingEdits {
  onEdit: (world: WorldSpec, done: boolean) => void;
  newKind: () => Region["kind"];
}

const isCssColor = (name: string): boolean => typeof CSS !== "undefined" && CSS.supports("color", name);

const finite = (...values: (number | undefined)[]): boolean =>
  values.every((v) => v !== undefined && Number.isFinite(v));

export interface WorldDrawing {
  element: HTMLElement;
  draw: (world: WorldSpec) => void;
}

export function worldDrawing(edits?: DrawingEdits): WorldDrawing {
  const element = host(html`<div class="world-drawing"></div>`);
  const pointer = edits ? dragging(edits) : null;
  const draw = (world: WorldSpec) => {
    if (pointer) pointer.current = world;
    render(drawingTemplate(world, pointer), element);
  };
  return { element, draw };
}

function drawingTemplate(world: WorldSpec, pointer: Dragging | null) {
  const { width, height } = world;
  const drawable = finite(width, height) && width > 0 && height > 0;
  const size = Math.min(width, height);
  // A margin, so that a start on the edge is drawn whole.
  const margin = size / 20;
  const regions = (world.regions ?? []).filter((r) => r.rect.length === 4 && finite(...r.rect));
  return html`<svg
      class="world-svg ${pointer ? "editable" : ""}"
      role="img"
      aria-labelledby="world-drawing-title"
      style=${drawable ? "" : "display: none"}
      viewBox=${drawable ? `${-margin} ${-margin} ${width + 2 * margin} ${height + 2 * margin}` : "0 0 1 1"}
      preserveAspectRatio="xMidYMid meet"
      @pointerdown=${pointer?.down}
      @pointermove=${pointer?.move}
      @pointerup=${pointer?.end}
      @pointercancel=${pointer?.end}
    >
      ${drawable ? worldShapes(world, regions, pointer !== null) : nothing}
    </svg>
    <p class="hint" ?hidden=${drawable}>Enter a positive width and height to see the world.</p>
    <ul class="legend" aria-label="Colours of the drawing">
      <li><span class="swatch obstacle"></span>obstacle</li>
      <li><span class="swatch positive"></span>terminal, reward &gt; 0</li>
      <li><span class="swatch negative"></span>terminal, reward &lt; 0</li>
      <li><span class="swatch zone"></span>zone</li>
      <li><span class="swatch start"></span>start</li>
    </ul>`;
}

function worldShapes(world: WorldSpec, regions: Region[], editable: boolean) {
  const { width, height } = world;
  const size = Math.min(width, height);
  const line = size / 250;
  const flipY = (y: number) => height - y; // SVG's y points down, the world's up
  return svg`<title id="world-drawing-title">The world: ${width} by ${height}, ${regions.length} regions</title>
    <rect x="0" y="0" width=${width} height=${height} fill="#ffffff" stroke="#111827" stroke-width=${line * 3}></rect>
    <g class="grid" stroke="#9ca3af" stroke-width=${line}>
      ${gridLines(width, world.step).map((x) => svg`<line x1=${x} y1="0" x2=${x} y2=${height}></line>`)}
      ${gridLines(height, world.step).map((y) => svg`<line x1="0" y1=${flipY(y)} x2=${width} y2=${flipY(y)}></line>`)}
    </g>
    ${regions.map((region) => regionShape(region, (world.regions ?? []).indexOf(region), flipY, size, editable))}
    ${startMark(world.start ?? [0, 0], flipY, size)}`;
}

function regionShape(region: Region, index: number, flipY: (y: number) => number, size: number, editable: boolean) {
  const [x0, y0, x1, y1] = region.rect as [number, number, number, number];
  const line = size / 250;
  const fills = regionFills(region, isCssColor);
  const band = (x1 - x0) / fills.length;
  const handle = Math.min(size / 30, (x1 - x0) / 3, (y1 - y0) / 3);
  // Small enough for the whole name to fit across its region (a character is about 0.6 em wide): a label
  // wider than a region at the world's edge would be cut off by the drawing's border.
  const fontSize = Math.min(size / 22, (x1 - x0) / 4, (0.9 * (x1 - x0)) / (0.6 * Math.max(1, region.name.length)));
  // White on the dark fills (obstacles, terminals), ink on the light ones.
  const ink = region.kind === "obstacle" || region.kind === "terminal" ? "#ffffff" : "#0b0f19";
  return svg`<g class="region region-${region.kind}" data-region=${region.name} data-index=${index}>
    ${fills.map(
      (f, i) =>
        svg`<rect x=${x0 + i * band} y=${flipY(y1)} width=${band} height=${y1 - y0} fill=${f.color} fill-opacity=${f.opacity}></rect>`,
    )}
    <rect x=${x0} y=${flipY(y1)} width=${x1 - x0} height=${y1 - y0} fill="none" stroke="#111827" stroke-width=${line * 1.5}></rect>
    <text x=${(x0 + x1) / 2} y=${flipY((y0 + y1) / 2)} font-size=${fontSize} text-anchor="middle" dominant-baseline="central" class="region-label" fill=${ink}>${region.name}</text>
    ${
      editable
        ? CORNERS.map(
            (corner) =>
              svg`<rect class="handle handle-${corner}" data-corner=${corner} x=${(corner.startsWith("x0") ? x0 : x1) - handle / 2} y=${flipY(corner.endsWith("y0") ? y0 : y1) - handle / 2} width=${handle} height=${handle} fill="#ffffff" stroke="#111827" stroke-width=${line}></rect>`,
          )
        : nothing
    }
  </g>`;
}

function startMark(start: number[], flipY: (y: number) => number, size: number) {
  if (start.length === 4 && finite(...start)) {
    const [x0, y0, x1, y1] = start as [number, number, number, number];
    return svg`<rect class="start" x=${x0} y=${flipY(y1)} width=${x1 - x0} height=${y1 - y0} fill="#2563eb" fill-opacity="0.15" stroke="#1d4ed8" stroke-width=${size / 120} stroke-dasharray=${`${size / 40} ${size / 60}`}></rect>`;
  }
  const [x, y] = start;
  if (!finite(x, y)) return nothing;
  return svg`<circle class="start" cx=${x} cy=${flipY(y as number)} r=${size / 24} fill="#1d4ed8" stroke="#ffffff" stroke-width=${size / 150}></circle>`;
}

/** The pointer's handlers on an editable drawing, and the world it shows now. */
interface Dragging {
  current: WorldSpec | null;
  down: (event: PointerEvent) => void;
  move: (event: PointerEvent) => void;
  end: (event: PointerEvent) => void;
}

function dragging(edits: DrawingEdits): Dragging {
  let drag: Drag | null = null;
  let before: WorldSpec | null = null;
  let next: WorldSpec | null = null;
  const state: Dragging = { current: null, down: () => {}, move: () => {}, end: () => {} };
  /** The pointer's position in world units (y up). */
  const toWorld = (event: PointerEvent): [number, number] => {
    const matrix = (event.currentTarget as SVGSVGElement).getScreenCTM()?.inverse();
    const point = new DOMPoint(event.clientX, event.clientY).matrixTransform(matrix);
    return [point.x, (state.current?.height ?? 0) - point.y];
  };
  const edited = (world: WorldSpec, index: number, rect: Rect): WorldSpec => ({
    ...world,
    regions: (world.regions ?? []).map((r, i) => (i === index ? { ...r, rect } : r)),
  });
  state.down = (event) => {
    const current = state.current;
    if (event.button !== 0 || !current) return;
    const at = toWorld(event);
    const target = event.target as Element;
    const index = Number(target.closest("[data-index]")?.getAttribute("data-index") ?? -1);
    const rect = current.regions?.[index]?.rect as Rect | undefined;
    const corner = target.getAttribute("data-corner") as Corner | null;
    if (rect && corner) drag = { mode: "resize", index, corner, rect, moved: false };
    else if (rect) drag = { mode: "move", index, from: at, rect, moved: false };
    else drag = { mode: "new", from: at, moved: false };
    before = current;
    next = null;
    (event.currentTarget as SVGSVGElement).setPointerCapture(event.pointerId);
    event.preventDefault();
  };
  state.move = (event) => {
    if (!drag || !before) return;
    const at = toWorld(event);
    const base = before;
    if (drag.mode === "new") {
      drag.moved ||= Math.hypot(at[0] - drag.from[0], at[1] - drag.from[1]) > base.step / 3;
      if (!drag.moved) return;
      const regions = base.regions ?? [];
      next = { ...base, regions: [...regions, newRegion(edits.newKind(), rectFrom(drag.from, at, base), regions)] };
    } else if (drag.mode === "move") {
      drag.moved = true;
      next = edited(base, drag.index, moveRect(drag.rect, at[0] - drag.from[0], at[1] - drag.from[1], base));
    } else {
      drag.moved = true;
      next = edited(base, drag.index, resizeRect(drag.rect, drag.corner, at, base));
    }
    edits.onEdit(next, false);
  };
  state.end = (event) => {
    if (!drag || !before) return;
    const wasClick = drag.mode === "new" && !drag.moved;
    if (wasClick && event.type === "pointerup") next = { ...before, start: startAt(toWorld(event), before) };
    drag = null;
    if (next) edits.onEdit(next, true);
    before = next = null;
  };
  return state;
}
