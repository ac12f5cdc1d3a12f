/** Runs in the list: their speed choices, the filter, and how long a run will take at a speed. */
import type { RunBrief } from "../api/types";
import { formatCount, formatNumber } from "./format";
import { formatDuration } from "./protocol";

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

/** The speed to watch a run at when nothing says otherwise: each move can be followed. */
export const WATCH_HZ = 20;

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

/** A protocol that would take longer than this at the speed chosen is described by its pace, not its end. */
export const PATIENT_SECONDS = 3600;

/**
 * The launcher's line on how long a run takes: `episodes` (undefined or 0: until paused) of at most
 * `maxSteps` steps at `hz` steps/s (null: full speed, about `fullSpeedHz`). A speed too slow to finish
 * within PATIENT_SECONDS is described by what one watches at it (episodes a minute) and full speed's time,
 * not by "up to 444 h".
 */
export function launchEstimate(
  episodes: number | undefined,
  maxSteps: number,
  hz: number | null,
  fullSpeedHz: number,
): string {
  if (episodes === undefined || episodes <= 0) return "Runs until paused (no episode count).";
  const head = `${formatCount(episodes)} episodes of up to ${formatCount(maxSteps)} steps`;
  const full = formatDuration(runDuration(episodes, maxSteps, null, fullSpeedHz));
  if (hz === null || hz <= 0) return `${head}: about ${full} at full speed.`;
  const at = runDuration(episodes, maxSteps, hz, fullSpeedHz);
  const speed = `${hz} steps/s`;
  if (at <= PATIENT_SECONDS) return `${head}: up to ${formatDuration(at)} at ${speed} (full speed: about ${full}).`;
  const perMinute = (60 * hz) / Math.max(1, maxSteps);
  const pace =
    perMinute >= 1
      ? `at least ${formatCount(Math.floor(perMinute))} episode${perMinute >= 2 ? "s" : ""} a minute`
      : `an episode in up to ${formatDuration(maxSteps / hz)}`;
  return `${head}. At ${speed}: ${pace}, to watch; the whole protocol needs more than an hour at this speed (full speed: about ${full}).`;
}
