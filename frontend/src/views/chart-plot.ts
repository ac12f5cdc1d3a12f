/** One demon's chart of views/charts.ts: its uPlot plot, built for its colour, font and scale, then fed. */
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import type { AppState } from "../app/app";
import type { History, Run } from "../api/types";
import { formatCount, formatNumber } from "../lib/format";
import { type EvaluationMark, alignHistories, decadeTicks, markColumns, powerLabel, spansDecades } from "../lib/series";
import type { Scope } from "../ui/scope";
import { lineLook, plotSize, remPx } from "./plots";

const FALLBACK_COLOUR = "#0072B2";
const TRUTH_COLOUR = "#111827";

/** A charted demon: its figure's parts, its plot and what its caption says. */
export interface Multiple {
  demon: string;
  /** its plot's life: released when the demon is no longer charted */
  scope: Scope;
  box?: HTMLElement;
  plot: uPlot | null;
  /** what the plot was built for (colour, font size, scale): rebuilt when it changes */
  key: string;
  caption: string;
  colour?: string;
  /** how many evaluations the chart shows (the browser tests read it: a canvas has no text to find) */
  marks?: number;
  resize?: () => void;
}

/** A chart cell's plot: as wide as its cell, 0.55 of that high, at least 9 rem. */
const chartSize = (box: HTMLElement) => plotSize(box, 9, 0.55);

export function drawMultiple(
  multiple: Multiple,
  history: History,
  marks: readonly EvaluationMark[],
  state: AppState,
): void {
  const box = multiple.box as HTMLElement;
  const demon = state.demons.find((d) => d.name === multiple.demon);
  const colour = demon?.colour ?? FALLBACK_COLOUR;
  const [steps, values] = alignHistories([history], "prediction") as [number[], (number | null)[]];
  const columns = markColumns(steps, marks);
  const data: uPlot.AlignedData = [steps, values, ...columns];
  multiple.marks = columns[0]?.filter((v) => v !== null).length ?? 0;
  const log = spansDecades([...values, ...columns.flat()]);
  multiple.caption = captionText(marks.at(-1), state.evaluations[multiple.demon]?.exact != null, state.run, log);
  multiple.colour = colour;
  const font = remPx();
  const key = `${colour}|${font}|${log}`;
  if (multiple.plot && multiple.key === key) {
    multiple.plot.setData(data);
    return;
  }
  multiple.plot?.destroy();
  multiple.key = key;
  const plot = new uPlot({ ...chartSize(box), ...plotOptions(colour, font, log) }, data, box);
  multiple.plot = plot;
  multiple.resize = () => plot.setSize(chartSize(box));
}

function plotOptions(colour: string, font: number, log: boolean): Omit<uPlot.Options, "width" | "height"> {
  const dot = (size: number, stroke: string, fill: string): uPlot.Series => ({
    stroke,
    width: 2,
    paths: () => null,
    points: { show: true, size, stroke, fill, width: 2 },
  });
  // The interval's ends count for the y range but are drawn as the truth's bar (whiskers), not as points.
  const end: uPlot.Series = { stroke: "transparent", paths: () => null, points: { show: false } };
  const series: uPlot.Series[] = [
    { label: "step" },
    { label: "prediction", stroke: colour, width: 2.5, spanGaps: false },
    { label: "evaluated: prediction", ...dot(Math.round(0.75 * font), colour, "#ffffff") },
    { label: "evaluated: truth", ...dot(Math.round(0.55 * font), TRUTH_COLOUR, TRUTH_COLOUR) },
    { label: "low", ...end },
    { label: "high", ...end },
  ];
  const look = lineLook("step");
  if (log) {
    look.scales = { ...look.scales, y: { distr: 4, asinh: 1 } }; // linear within ±1, log beyond
    const [xAxis, yAxis] = look.axes ?? [];
    look.axes = [
      xAxis ?? {},
      {
        ...yAxis,
        space: 16, // a few powers of ten, each label a line apart
        splits: (_u, _a, min, max) => decadeTicks(min, max),
        values: (_u, ticks) => ticks.map(powerLabel),
      },
    ];
  }
  return { ...look, title: undefined, series, hooks: { draw: [...(look.hooks?.draw ?? []), drawTruthBars] } };
}

/** The truth's 95 % bars: a vertical line from low to high at each evaluation's step. */
function drawTruthBars(u: uPlot): void {
  const [steps, , , , lows, highs] = u.data;
  if (!lows || !highs) return;
  const ctx = u.ctx;
  ctx.save();
  ctx.strokeStyle = TRUTH_COLOUR;
  ctx.lineWidth = 2 * devicePixelRatio;
  steps.forEach((step, i) => {
    const low = lows[i];
    const high = highs[i];
    if (low === null || low === undefined || high === null || high === undefined || low === high) return;
    const x = u.valToPos(step, "x", true);
    const cap = 4 * devicePixelRatio;
    ctx.beginPath();
    for (const value of [low, high]) {
      const y = u.valToPos(value, "y", true);
      ctx.moveTo(x - cap, y);
      ctx.lineTo(x + cap, y);
    }
    ctx.moveTo(x, u.valToPos(low, "y", true));
    ctx.lineTo(x, u.valToPos(high, "y", true));
    ctx.stroke();
  });
  ctx.restore();
}

/** Where an evaluation's prediction and truth are taken on this run's world, for the captions. */
export function evaluatedFrom(run: Run | null): string {
  return run?.evaluation?.kind === "rollouts" ? "from the agent's state" : "from the start";
}

/** The caption's words after the name: the latest evaluation's pair, and the log scale if it is one. */
export function captionText(latest: EvaluationMark | undefined, exact: boolean, run: Run | null, log: boolean): string {
  const [truth, , high] = latest?.truth ?? [];
  const pair =
    latest && truth !== undefined && high !== undefined
      ? ` · ${evaluatedFrom(run)} at step ${formatCount(latest.step)}: truth ${formatNumber(truth)}${exact ? " (exact)" : ` ± ${formatNumber(high - truth)}`}, prediction ${formatNumber(latest.prediction)}`
      : "";
  return pair + (log ? " · log scale: the values span many powers of ten" : "");
}
