/** Runs in the list: their speed choices, the filter, and how long a run will take at a speed. */
import type { RunBrief } from "../api/types";
import { formatNumber } from "./format";

/** The speed select's value for "as fast as possible" (hz null on the wire). */
export const FULL_SPEED = "full";
/** Steps per second offered: slow enough to follow the agent, up to fast enough to see learning. */
export const SPEEDS = [2, 5, 10, 20, 50, 100, 200, 1000];

export interface SpeedChoice {
  /** changes when the items change (a run at a speed not in SPEEDS adds it) */
  key: string;
  items: [string, string][];
  value: string;
}

export function speedChoice(hz: number | null | undefined): SpeedChoice {
  const speeds = hz == null || SPEEDS.includes(hz) ? SPEEDS : [...SPEEDS, hz].sort((a, b) => a - b);
  const items: [string, string][] = [
    ...speeds.map((s): [string, string] => [String(s), `${formatNumber(s, s >= 10 ? 0 : 1)} steps/s`]),
    [FULL_SPEED, "full speed"],
  ];
  return { key: speeds.join(","), items, value: hz == null ? FULL_SPEED : String(hz) };
}

/** Whether every word of `query` is found in the run's name, id, status or demon names (case ignored). */
export function matchesFilter(run: Pick<RunBrief, "id" | "name" | "status" | "demons">, query: string): boolean {
  const words = query.toLowerCase().split(/\s+/).filter(Boolean);
  if (words.length === 0) return true;
  const text = [run.name ?? "", run.id, run.status, ...run.demons].join(" ").toLowerCase();
  return words.every((word) => text.includes(word));
}

/** A protocol this long (in steps, at most) is better run at full speed than watched. */
export const WATCHABLE_SECONDS = 600;

/**
 * How long `episodes` episodes of at most `maxSteps` steps take at `hz` steps per second (null: full
 * speed, about `fullSpeedHz`). Episodes often end early, so this is an upper bound.
 */
export function runDuration(episodes: number, maxSteps: number, hz: number | null, fullSpeedHz: number): number {
  const steps = Math.max(0, episodes) * Math.max(0, maxSteps);
  return steps / (hz !== null && hz > 0 ? hz : fullSpeedHz);
}
