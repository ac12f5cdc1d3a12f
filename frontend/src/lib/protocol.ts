/**
 * A protocol job as the Protocol tab shows it: its progress line, its results table (the rows of
 * `horde run`'s table) and the test-run counts beside the thesis's. Pure functions of the server's
 * answer (GET /api/protocols/{id}), so that they are tested without a browser.
 */
import type { Counts, DemonResult, Protocol } from "../api/types";
import { MISSING, formatCount, formatCountOf, formatEstimate, formatNumber, formatRelativeError } from "./format";

/** A duration for people: "0.4 s", "42 s", "2 min 05 s", "1 h 03 min". */
export function formatDuration(seconds: number | null | undefined): string {
  if (seconds === null || seconds === undefined || !Number.isFinite(seconds) || seconds < 0) return MISSING;
  if (seconds < 9.95) return `${seconds.toFixed(1)} s`;
  const whole = Math.round(seconds);
  if (whole < 60) return `${whole} s`;
  if (whole < 3600) return `${Math.floor(whole / 60)} min ${String(whole % 60).padStart(2, "0")} s`;
  const minutes = Math.round(whole / 60);
  return `${Math.floor(minutes / 60)} h ${String(minutes % 60).padStart(2, "0")} min`;
}

export interface ProgressView {
  /** episodes done out of all, in [0, 1] (for a <progress> element) */
  fraction: number;
  /** "150 / 3,000 episodes · 5 %" */
  counted: string;
  /** how long it has taken and what is left or happening: "1.2 s elapsed · about 22 s left" */
  timing: string;
}

type ProgressOf = Pick<Protocol, "status" | "episodes_done" | "episodes_total" | "seconds">;

/**
 * The progress of a job. `elapsed` (seconds by the browser's clock) is used while it runs; a
 * finished job reports the server's own time. Once every episode is done the job still computes the
 * Monte-Carlo truth and the test runs, which report no progress of their own: the line says so.
 */
export function protocolProgress(job: ProgressOf, elapsed: number | null): ProgressView {
  const total = Math.max(0, job.episodes_total);
  const done = Math.min(Math.max(0, job.episodes_done), total);
  const fraction = total > 0 ? done / total : job.status === "finished" ? 1 : 0;
  const counted = `${formatCount(done)} / ${formatCount(total)} episodes · ${Math.floor(100 * fraction)} %`;
  let timing: string;
  switch (job.status) {
    case "running": {
      const parts = [elapsed !== null ? `${formatDuration(elapsed)} elapsed` : null];
      if (done >= total) parts.push("evaluating: Monte-Carlo truth and test runs");
      else if (done > 0 && elapsed !== null && elapsed > 0) {
        parts.push(`about ${formatDuration((elapsed * (total - done)) / done)} left`);
      }
      timing = parts.filter((p) => p !== null).join(" · ");
      break;
    }
    case "finished":
      timing = job.seconds !== null ? `finished in ${formatDuration(job.seconds)}` : "finished";
      break;
    case "cancelled":
      timing = "cancelled";
      break;
    case "interrupted":
      timing = "interrupted: the server stopped while it ran";
      break;
    case "failed":
      timing = "failed";
      break;
  }
  return { fraction, counted, timing };
}

export interface ResultRow {
  name: string;
  prediction: string;
  /** "39.012 ± 0.210" */
  truth: string;
  /** prediction - truth */
  error: string;
  /** the error relative to |truth|: "+4.2 %" */
  relative: string;
  thesis: string;
}

/** One row per demon, as `horde run` prints them (a dash where there is no truth or thesis number). */
export function resultRows(results: readonly DemonResult[]): ResultRow[] {
  return results.map((d) => ({
    name: d.name,
    prediction: formatNumber(d.prediction),
    truth: formatEstimate(d.truth, d.truth_stderr),
    error: formatNumber(d.error),
    relative: formatRelativeError(d.prediction, d.truth),
    thesis: formatNumber(d.thesis),
  }));
}

export interface CountsRow {
  /** whose counts */
  key: "protocol" | "thesis";
  label: string;
  positive: string;
  negative: string;
  none: string;
}

export interface CountsTable {
  /** the demon whose greedy policy the test runs follow */
  demon: string;
  rows: CountsRow[];
}

/** A count with its share of all test runs ("10 (100 %)"), so that 1 trial compares with the thesis's 10. */
export function formatShare(count: number, total: number): string {
  return total > 0 ? `${formatCount(count)} (${Math.round((100 * count) / total)} %)` : formatCount(count);
}

function countsRow(key: CountsRow["key"], label: string, counts: Counts): CountsRow {
  const total = counts.positive + counts.negative + counts.none;
  return {
    key,
    label,
    positive: formatShare(counts.positive, total),
    negative: formatShare(counts.negative, total),
    none: formatShare(counts.none, total),
  };
}

/**
 * Where the greedy test runs of a control protocol ended (positive terminal, negative, none within
 * the step limit), this protocol's beside the thesis's; null for a protocol without test runs.
 */
export function countsTable(results: readonly DemonResult[], thesis: Counts | null | undefined): CountsTable | null {
  const tested = results.find((d) => d.counts);
  if (!tested?.counts) return null;
  const rows = [countsRow("protocol", "this protocol", tested.counts)];
  if (thesis) rows.push(countsRow("thesis", "the thesis", thesis));
  return { demon: tested.name, rows };
}

/** What was run: "experiment3: 1 trial × 300 episodes (at most 100 steps each)". */
export function protocolTitle(job: Pick<Protocol, "name" | "trials" | "episodes" | "max_steps">): string {
  return `${job.name ?? "protocol"}: ${formatCountOf(job.trials, "trial")} × ${formatCountOf(job.episodes, "episode")} (at most ${formatCountOf(job.max_steps, "step")} each)`;
}

/** The line under the table: "8,981 steps in 0.4 s (20,505 steps/s); truth: 5,000 rollouts per trial". */
export function protocolSummary(job: Pick<Protocol, "steps" | "seconds" | "rollouts">): string {
  const parts: string[] = [];
  if (job.steps !== null) {
    const speed = job.seconds ? ` (${formatCount(job.steps / job.seconds)} steps/s)` : "";
    parts.push(`${formatCountOf(job.steps, "step")} in ${formatDuration(job.seconds)}${speed}`);
  }
  parts.push(
    job.rollouts > 0
      ? `truth: ${formatCountOf(job.rollouts, "Monte-Carlo rollout")} per trial`
      : "no Monte-Carlo truth (the scenario asks for 0 rollouts)",
  );
  return parts.join("; ");
}
