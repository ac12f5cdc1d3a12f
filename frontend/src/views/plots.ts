/**
 * What the dashboard's line plots (uPlot: the charted demons, the stream strip) share: sizes in the root
 * font's units, so that large text grows the plots, and one look for legend, cursor and axes.
 */

import type uPlot from "uplot";
import { tickLabels } from "../lib/axis";

/** Pixels of one rem (the root font size the user chose). */
export function remPx(): number {
  return parseFloat(getComputedStyle(document.documentElement).fontSize) || 16;
}

/** A plot as wide as `box`, `ratio` of that high, between `minRem` and 14 rem. */
export function plotSize(box: HTMLElement, minRem: number, ratio: number): { width: number; height: number } {
  const width = Math.max(160, Math.floor(box.clientWidth));
  return { width, height: Math.round(Math.min(14 * remPx(), Math.max(minRem * remPx(), width * ratio))) };
}

/** No legend or cursor, a numeric x axis labelled `xLabel`, both axes lettered in the root font with compact
 * labels (500k, 1M; the decimals the tick step needs) and room between two x labels for the widest ("1.25M"). */
export function lineLook(xLabel: string): Pick<uPlot.Options, "legend" | "cursor" | "scales" | "axes" | "hooks"> {
  const font = remPx();
  const axisFont = `${Math.round(0.8 * font)}px system-ui`;
  const values = (u: uPlot, ticks: number[], axis: number) => {
    const labels = tickLabels(ticks);
    drawnTicks.set(u, { ...drawnTicks.get(u), [axis]: ticks.map((tick, i) => [labels[i] ?? "", tick]) });
    return labels;
  };
  const axis = { stroke: "#111827", grid: { stroke: "#e5e7eb" }, font: axisFont, labelFont: `bold ${axisFont}` };
  return {
    legend: { show: false },
    cursor: { show: false },
    scales: { x: { time: false } },
    hooks: { draw: [showTicks] },
    axes: [
      { ...axis, label: xLabel, size: Math.round(2.6 * font), space: Math.round(4.5 * font), values },
      { ...axis, size: (_u: uPlot, labels: string[] | null) => yAxisSize(labels, axisFont, font), values },
    ],
  };
}

/** Each plot's tick labels and values as last drawn, by axis (0: x, 1: y). */
const drawnTicks = new WeakMap<uPlot, Record<number, [string, number][]>>();

/** The labels drawn on the axes and where (CSS px from the plot's left or top), on the plot's element as
 * `data-x-ticks` and `data-y-ticks`: a canvas holds no text that a browser test could read. */
function showTicks(u: uPlot): void {
  const ticks = drawnTicks.get(u) ?? {};
  const at = (axis: number, scale: "x" | "y") =>
    JSON.stringify((ticks[axis] ?? []).map(([label, value]) => [label, Math.round(u.valToPos(value, scale))]));
  u.root.dataset.xTicks = at(0, "x");
  u.root.dataset.yTicks = at(1, "y");
}

let measuring: CanvasRenderingContext2D | null = null;

/** The y axis's width: its widest label in `axisFont` and room for the ticks, at least 3.6 rem (so that
 * "0.00050" is never cut to "00050" by the plot's left edge). */
function yAxisSize(labels: string[] | null, axisFont: string, font: number): number {
  measuring ??= document.createElement("canvas").getContext("2d");
  if (!measuring || !labels) return Math.round(3.6 * font);
  measuring.font = axisFont;
  const widest = Math.max(0, ...labels.map((label) => measuring?.measureText(label).width ?? 0));
  return Math.max(Math.round(3.6 * font), Math.ceil(widest + 1.4 * font));
}
