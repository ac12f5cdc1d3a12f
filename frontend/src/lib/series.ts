/** Histories of several demons as one uPlot data table, thinned to what a chart can show. */
import type { History } from "../api/types";

export type Metric = "prediction" | "rupee" | "ude" | "delta" | "cumulant";

/** [x, y_1, ..., y_n]: uPlot's column layout; null leaves a gap. */
export type ChartData = [number[], ...(number | null)[][]];

/**
 * One metric of each history against the steps. The histories come from the same run buffer, so
 * their rows line up from the newest back; a history that is longer (read a moment later) is cut.
 */
export function alignHistories(histories: readonly History[], metric: Metric, maxPoints = 800): ChartData {
  if (histories.length === 0) return [[]];
  const length = Math.min(...histories.map((h) => h.step.length));
  const first = histories[0] as History;
  const steps = first.step.slice(first.step.length - length);
  const columns = histories.map((h) => h[metric].slice(h[metric].length - length));
  const keep = strideIndices(length, maxPoints);
  return [keep.map((i) => steps[i] as number), ...columns.map((c) => keep.map((i) => c[i] ?? null))];
}

/** Indices 0..length-1 thinned to at most maxPoints, evenly spread, always keeping the newest. */
export function strideIndices(length: number, maxPoints: number): number[] {
  if (length <= 0) return [];
  if (length <= maxPoints) return Array.from({ length }, (_, i) => i);
  const stride = (length - 1) / (maxPoints - 1);
  return Array.from({ length: maxPoints }, (_, k) => Math.round(k * stride));
}

/**
 * Whether a chart of these values wants a logarithmic axis: the largest magnitude is at least a thousand and
 * a thousand times the smallest (or 1, whichever is larger), as a diverging demon's predictions are (Baird's
 * counterexample: 3 to 10^11). The chart then uses uPlot's asinh scale: linear within ±1, logarithmic beyond,
 * so that signs and zero survive.
 */
export function spansDecades(values: readonly (number | null)[]): boolean {
  const sizes = values.filter((v): v is number => v !== null && Number.isFinite(v)).map(Math.abs);
  if (sizes.length === 0) return false;
  const largest = Math.max(...sizes);
  return largest >= 1e3 && largest >= 1e3 * Math.max(1, Math.min(...sizes));
}

/** A log axis's ticks within [min, max]: 0 and two or three powers of ten on each side (a small chart has
 * room for few labels; uPlot leaves out, as null, those that would overlap). */
export function decadeTicks(min: number, max: number): number[] {
  const top = Math.ceil(Math.log10(Math.max(Math.abs(min), Math.abs(max), 1)));
  const stride = Math.max(1, Math.ceil(top / 2));
  const ticks = min <= 0 && max >= 0 ? [0] : [];
  for (let k = top > 2 ? stride : 0; k <= top; k += stride) {
    if (10 ** k <= max && 10 ** k >= min) ticks.push(10 ** k);
    if (-(10 ** k) >= min && -(10 ** k) <= max) ticks.unshift(-(10 ** k));
  }
  return ticks;
}

/** A log axis's label: 0, 1, 10, 100, 1000, then 1e4, 1e5, ... (and their negatives); none for a tick left out. */
export function powerLabel(value: number | null): string {
  if (value === null) return "";
  if (value === 0) return "0";
  const size = Math.abs(value);
  const text = size < 1e4 ? String(size) : `1e${Math.round(Math.log10(size))}`;
  return value < 0 ? `-${text}` : text;
}

/** An evaluation drawn on a chart: at the step it was made, the prediction and the truth from the same state. */
export interface EvaluationMark {
  step: number;
  prediction: number | null;
  /** the truth and its 95 % interval (all three equal when exact) */
  truth: [number, number, number];
}

/**
 * The marks as four columns beside `steps` (prediction, truth, low, high), each mark at the row of the step
 * nearest its own; null elsewhere. A mark older than the first step has no row and is left out (the history
 * no longer reaches back to it); a later one sits on the last row until the next reading. Of two marks on
 * one row the later wins.
 */
export function markColumns(steps: readonly number[], marks: readonly EvaluationMark[]): (number | null)[][] {
  const columns = [0, 1, 2, 3].map(() => steps.map((): number | null => null));
  const first = steps[0];
  if (first === undefined) return columns;
  for (const mark of marks) {
    if (mark.step < first) continue;
    let at = 0;
    for (let i = 1; i < steps.length; i++) {
      if (Math.abs((steps[i] as number) - mark.step) < Math.abs((steps[at] as number) - mark.step)) at = i;
    }
    const values = [mark.prediction, ...mark.truth];
    columns.forEach((column, k) => (column[at] = values[k] ?? null));
  }
  return columns;
}
