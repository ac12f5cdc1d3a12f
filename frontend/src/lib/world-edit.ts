/**
 * Editing a world by hand on its drawing: drawing a new region, moving or resizing one, setting the
 * start; everything snapped to the world's step grid and kept inside the world. Pure functions of the
 * world and the pointer's positions in world units, tested without a browser.
 */
import type { Region, WorldSpec } from "../api/types";

export type Rect = [number, number, number, number];
/** A corner of a rectangle: which of x0/x1 and y0/y1 it moves. */
export type Corner = "x0y0" | "x1y0" | "x0y1" | "x1y1";

/** `value` to the nearest multiple of `step` (the value itself when the step is not positive). */
export function snap(value: number, step: number): number {
  return step > 0 ? Math.round(value / step) * step : value;
}

function clamp(value: number, low: number, high: number): number {
  return Math.min(high, Math.max(low, value));
}

/** A rectangle from two corners in any order, snapped and inside the world, at least one step wide. */
export function rectFrom(
  a: [number, number],
  b: [number, number],
  world: Pick<WorldSpec, "width" | "height" | "step">,
): Rect {
  const { width, height, step } = world;
  let [x0, x1] = [snap(Math.min(a[0], b[0]), step), snap(Math.max(a[0], b[0]), step)];
  let [y0, y1] = [snap(Math.min(a[1], b[1]), step), snap(Math.max(a[1], b[1]), step)];
  x0 = clamp(x0, 0, width - step);
  y0 = clamp(y0, 0, height - step);
  x1 = clamp(Math.max(x1, x0 + step), step, width);
  y1 = clamp(Math.max(y1, y0 + step), step, height);
  return [x0, y0, x1, y1];
}

/** `rect` moved by (dx, dy), snapped, kept whole inside the world. */
export function moveRect(
  rect: Rect,
  dx: number,
  dy: number,
  world: Pick<WorldSpec, "width" | "height" | "step">,
): Rect {
  const [x0, y0, x1, y1] = rect;
  const w = x1 - x0;
  const h = y1 - y0;
  const nx = clamp(snap(x0 + dx, world.step), 0, world.width - w);
  const ny = clamp(snap(y0 + dy, world.step), 0, world.height - h);
  return [nx, ny, nx + w, ny + h];
}

/** `rect` with one corner dragged to `to` (the opposite corner stays). */
export function resizeRect(
  rect: Rect,
  corner: Corner,
  to: [number, number],
  world: Pick<WorldSpec, "width" | "height" | "step">,
): Rect {
  const [x0, y0, x1, y1] = rect;
  const fixed: [number, number] = [corner.startsWith("x0") ? x1 : x0, corner.endsWith("y0") ? y1 : y0];
  return rectFrom(fixed, to, world);
}

/** The start point nearest to `at` on the lattice the agent moves on (multiples of step from the origin). */
export function startAt(at: [number, number], world: Pick<WorldSpec, "width" | "height" | "step">): [number, number] {
  const { width, height, step } = world;
  const last = (size: number) => (step > 0 ? Math.ceil(size / step) * step - step : size);
  return [clamp(snap(at[0], step), 0, last(width)), clamp(snap(at[1], step), 0, last(height))];
}

/** A fresh name for a region of `kind`: "obstacle1", "obstacle2", ... skipping the names in use. */
export function freshName(kind: Region["kind"], regions: readonly Pick<Region, "name">[]): string {
  const taken = new Set(regions.map((r) => r.name));
  for (let i = 1; ; i++) if (!taken.has(`${kind}${i}`)) return `${kind}${i}`;
}

/** The region a new drawing makes: a terminal rewards 1, an indicator is yellow or purple at even odds. */
export function newRegion(kind: Region["kind"], rect: Rect, regions: readonly Pick<Region, "name">[]): Region {
  const name = freshName(kind, regions);
  if (kind === "terminal") return { name, kind, rect, reward: 1 };
  if (kind === "indicator") {
    return {
      name,
      kind,
      rect,
      colors: [
        { name: "yellow", value: 1, probability: 0.5 },
        { name: "purple", value: -1, probability: 0.5 },
      ],
    } as Region;
  }
  return { name, kind, rect };
}
