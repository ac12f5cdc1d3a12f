/**
 * Facts about a world that the forms and the drawing need: its sensors, its start point, the grid of
 * its steps and the colours of its regions.
 */
import type { Region, WorldSpec } from "../api/types";

/**
 * The sensors of a world, in the server's order (DESIGN section 2; `WorldSpec.sensor_names` in
 * backend/horde/spec.py): x, y, bump, steps, reward, in:<region>..., color:<indicator>..., terminal.
 */
export function sensorNames(world: Pick<WorldSpec, "regions">): string[] {
  const regions = world.regions ?? [];
  return [
    "x",
    "y",
    "bump",
    "steps",
    "reward",
    ...regions.map((r) => `in:${r.name}`),
    ...regions.filter((r) => r.kind === "indicator").map((r) => `color:${r.name}`),
    "terminal",
  ];
}

/** The point a question is evaluated from: the start point, or the centre of a start rectangle. */
export function startPoint(world: Pick<WorldSpec, "start">): [number, number] {
  const start = world.start ?? [0, 0];
  if (start.length >= 4) {
    const [x0 = 0, y0 = 0, x1 = 0, y1 = 0] = start;
    return [(x0 + x1) / 2, (y0 + y1) / 2];
  }
  return [start[0] ?? 0, start[1] ?? 0];
}

/** Grid line positions at multiples of `step` inside (0, size); none when they would be too dense. */
export function gridLines(size: number, step: number, maxLines = 200): number[] {
  if (!(size > 0) || !(step > 0) || size / step > maxLines) return [];
  const lines: number[] = [];
  for (let i = 1; i * step < size; i++) lines.push(i * step);
  return lines;
}

export interface Fill {
  color: string;
  opacity: number;
}

/** One colour per region kind, the same as the live view's (backend/horde/view/colors.py; a test holds the two
 * together). */
export const KIND_COLORS = {
  obstacle: "#5b6472",
  positive: "#15803d",
  negative: "#dc2626",
  neutral: "#6d28d9", // a terminal whose reward is 0 or depends on an indicator's colour
  zone: "#f97316",
  /** an indicator before its colour is drawn, or one whose colour is no CSS colour */
  undrawn: "#9ca3af",
} as const;
/** A zone is translucent: what lies under it shows through. */
export const ZONE_OPACITY = 0.55;

/**
 * How a region is drawn: obstacles grey, terminals green (positive reward) or red (negative), zones
 * translucent orange; indicators in their colours, one vertical band per colour (`isColor` says
 * whether a colour name is a CSS colour; others are drawn grey).
 */
export function regionFills(region: Region, isColor: (name: string) => boolean): Fill[] {
  switch (region.kind) {
    case "obstacle":
      return [{ color: KIND_COLORS.obstacle, opacity: 1 }];
    case "zone":
      return [{ color: KIND_COLORS.zone, opacity: ZONE_OPACITY }];
    case "terminal": {
      const reward = typeof region.reward === "number" ? region.reward : 0;
      const color = reward > 0 ? KIND_COLORS.positive : reward < 0 ? KIND_COLORS.negative : KIND_COLORS.neutral;
      return [{ color, opacity: 0.85 }];
    }
    case "indicator": {
      const colors = region.colors?.length ? region.colors : [{ name: "grey" }];
      return colors.map((c) => ({ color: isColor(c.name) ? c.name : KIND_COLORS.undrawn, opacity: 0.9 }));
    }
  }
}

/** The names of a world's regions, optionally of some kinds only. */
export function regionNames(world: Pick<WorldSpec, "regions">, kinds?: Region["kind"][]): string[] {
  return (world.regions ?? []).filter((r) => !kinds || kinds.includes(r.kind)).map((r) => r.name);
}
