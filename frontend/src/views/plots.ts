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
export function lineLook(xLabel: string): Pick<uPlot.Options, "legend" | "cursor" | "scales" | "axes"> {
  const font = remPx();
  const axisFont = `${Math.round(0.8 * font)}px system-ui`;
  const values = (_u: uPlot, ticks: number[]) => tickLabels(ticks);
  const axis = { stroke: "#111827", grid: { stroke: "#e5e7eb" }, font: axisFont, labelFont: `bold ${axisFont}` };
  return {
    legend: { show: false },
    cursor: { show: false },
    scales: { x: { time: false } },
    axes: [
      { ...axis, label: xLabel, size: Math.round(2.6 * font), space: Math.round(4.5 * font), values },
      { ...axis, size: Math.round(3.6 * font), values },
    ],
  };
}
