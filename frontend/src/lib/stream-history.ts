/**
 * The strip chart of a stream run (the nexting paper's figure), as data: a sensor's readings over the
 * record numbers, and a demon's prediction made on observing each record beside the discounted return that
 * followed it, computed afterwards by the server from the later records (null until it is known).
 */
import type { StreamHistory } from "../api/types";

/** uPlot's aligned columns: x, then one column per series (null: a gap). */
export type Columns = [number[], ...(number | null)[][]];

/** [record numbers, readings] of one sensor. */
export function sensorColumns(history: StreamHistory, sensor: string): Columns {
  return [history.records, history.sensors[sensor] ?? history.records.map(() => null)];
}

/** [record numbers, predictions, realised returns] of one demon (returns all null when unreadable). */
export function demonColumns(history: StreamHistory, demon: string): Columns {
  const none = history.records.map(() => null);
  return [history.records, history.predictions[demon] ?? none, history.returns[demon] ?? none];
}

/** How far a demon's predictions are from the returns that followed, over the records where both are known. */
export interface StripError {
  /** records compared */
  count: number;
  /** mean |prediction - realised return| over them (NaN when none) */
  meanAbsolute: number;
}

export function stripError(history: StreamHistory, demon: string): StripError {
  const predictions = history.predictions[demon] ?? [];
  const returns = history.returns[demon] ?? [];
  let count = 0;
  let total = 0;
  predictions.forEach((prediction, i) => {
    const realised = returns[i];
    if (prediction === null || realised === null || realised === undefined) return;
    count += 1;
    total += Math.abs(prediction - realised);
  });
  return { count, meanAbsolute: count > 0 ? total / count : NaN };
}

/** The names to ask for: the ticked ones still offered, else the first `fallback` offered; at most `max`. */
export function pickNames(
  offered: readonly string[],
  ticked: readonly string[],
  fallback: number,
  max: number,
): string[] {
  const kept = ticked.filter((name) => offered.includes(name));
  return (kept.length > 0 ? kept : offered.slice(0, fallback)).slice(0, max);
}
