/** How numbers, counts and statuses read on the dashboard: one place, so every table agrees. */
import type { RunStatus } from "../api/types";

export const MISSING = "–";

/** A number with `digits` decimals; very large or very small magnitudes in exponent form. */
export function formatNumber(value: number | null | undefined, digits = 3): string {
  if (value === null || value === undefined || !Number.isFinite(value)) return MISSING;
  const magnitude = Math.abs(value);
  if (magnitude !== 0 && (magnitude >= 1e6 || magnitude < 10 ** -digits)) return value.toExponential(2);
  // Magnitudes below 10^-digits took the exponent form above, so no "-0.000" can come out here.
  return value.toFixed(digits);
}

/** A whole count with thousands separators: 12,345. */
export function formatCount(value: number | null | undefined): string {
  if (value === null || value === undefined || !Number.isFinite(value)) return MISSING;
  return Math.round(value).toLocaleString("en-US");
}

/** A count and its noun, singular for one: "1 run", "12,345 steps", "2 configurations". */
export function formatCountOf(value: number, one: string, many = `${one}s`): string {
  return `${formatCount(value)} ${value === 1 ? one : many}`;
}

/** A Monte-Carlo mean with its standard error: "39.012 ± 0.210". */
export function formatEstimate(mean: number | null | undefined, stderr: number | null | undefined, digits = 3): string {
  if (mean === null || mean === undefined || !Number.isFinite(mean)) return MISSING;
  if (stderr === null || stderr === undefined || !Number.isFinite(stderr)) return formatNumber(mean, digits);
  return `${formatNumber(mean, digits)} ± ${formatNumber(stderr, digits)}`;
}

/** prediction - truth relative to |truth|, in percent with one decimal ("+4.2 %"). */
export function formatRelativeError(prediction: number | null | undefined, truth: number | null | undefined): string {
  if (prediction == null || truth == null || !Number.isFinite(prediction) || !Number.isFinite(truth) || truth === 0) {
    return MISSING;
  }
  const percent = (100 * (prediction - truth)) / Math.abs(truth);
  return `${percent >= 0 ? "+" : "−"}${Math.abs(percent).toFixed(1)} %`;
}

/** A run's speed: "20 steps/s", or "full speed" when it has no limit. */
export function formatHz(hz: number | null | undefined): string {
  if (hz === null || hz === undefined) return "full speed";
  return `${formatNumber(hz, hz >= 10 ? 0 : 1)} steps/s`;
}

const STATUS_LABELS: Record<RunStatus, string> = {
  created: "created",
  running: "running",
  paused: "paused",
  finished: "finished",
  failed: "failed",
};

export function formatStatus(status: RunStatus): string {
  return STATUS_LABELS[status] ?? status;
}

/**
 * A short label for a run: its name and the first characters of its id; a run without a name (made over
 * REST without one) is told apart by its demons.
 */
export function runLabel(run: { id: string; name?: string | null; demons?: readonly string[] }): string {
  const short = run.id.slice(0, 6);
  if (run.name) return `${run.name} · ${short}`;
  const demons = run.demons ?? [];
  if (demons.length === 0) return `${short} · no demons`;
  const first = demons.slice(0, 2).join(", ");
  return `${short} · ${first}${demons.length > 2 ? ` +${demons.length - 2}` : ""}`;
}

/** An evaluation's truth as shown: the exact answer where there is one ("16.021 exact"), else mean ± se. */
export function formatTruth(
  evaluation: { truth?: number | null; stderr?: number | null; exact?: number | null } | undefined,
): string {
  if (!evaluation) return MISSING;
  if (evaluation.exact !== null && evaluation.exact !== undefined) return `${formatNumber(evaluation.exact)} exact`;
  return formatEstimate(evaluation.truth, evaluation.stderr);
}

/** The truth an evaluation's error is measured against: the exact answer, else the Monte-Carlo mean. */
export function truthOf(evaluation: { truth?: number | null; exact?: number | null } | undefined): number | null {
  return evaluation?.exact ?? evaluation?.truth ?? null;
}

/** A name cut into the pieces a line may break between: after each "_", "-", "." or ":" ("steps_", "northeast"),
 * so that a long demon name wraps at its words and never inside one. */
export function nameParts(name: string): string[] {
  return name.split(/(?<=[_\-.:])/).filter((part) => part !== "");
}
