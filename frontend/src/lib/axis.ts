/**
 * Axis tick labels that fit a small chart: large numbers compact (500k, 1.5M), and as many decimals as the
 * step between two ticks needs, so that neighbours never read the same ("0, 0, 0" for 0, 0.0002, 0.0004).
 */

const UNITS: readonly [number, string][] = [
  [1e12, "T"],
  [1e9, "G"],
  [1e6, "M"],
  [1e3, "k"],
];
/** More decimals than this are never needed by a chart a few hundred pixels high. */
const MOST_DECIMALS = 12;

/** Decimals that tell apart ticks `step` apart: 0 for 1 or 500, 1 for 0.5, 2 for 0.25, 4 for 0.0002. */
export function tickDecimals(step: number): number {
  if (!Number.isFinite(step) || step <= 0) return 0;
  for (let decimals = 0; decimals < MOST_DECIMALS; decimals++) {
    const scaled = step * 10 ** decimals;
    if (Math.abs(scaled - Math.round(scaled)) < 1e-6 * Math.max(1, scaled)) return decimals;
  }
  return MOST_DECIMALS;
}

/** `value` with `decimals` decimals, never "-0". */
function fixed(value: number, decimals: number): string {
  const text = value.toFixed(decimals);
  return Number(text) === 0 ? (0).toFixed(decimals) : text;
}

/** `value` in the unit `size` (k, M, ...), with the decimals a step of `step` needs there, less trailing zeros. */
function compact(value: number, size: number, suffix: string, step: number): string {
  const text = fixed(value / size, tickDecimals(step / size));
  return `${text.includes(".") ? text.replace(/\.?0+$/, "") : text}${suffix}`;
}

/**
 * The labels of evenly spaced ticks, "" for a tick left out (null). Once the largest is at least 10,000 each
 * label takes its own unit (500k, 1M, 1.25M), with the decimals the step needs in it; below, every label
 * has the decimals the step needs (0.0000, 0.0002, 0.0004).
 */
export function tickLabels(ticks: readonly (number | null)[]): string[] {
  const values = ticks.filter((t): t is number => t !== null && Number.isFinite(t));
  const sorted = [...values].sort((a, b) => a - b);
  const gaps = sorted
    .slice(1)
    .map((t, i) => t - (sorted[i] as number))
    .filter((gap) => gap > 0);
  const step = gaps.length > 0 ? Math.min(...gaps) : 0;
  const large = Math.max(0, ...values.map(Math.abs)) >= 1e4;
  return ticks.map((t) => {
    if (t === null || !Number.isFinite(t)) return "";
    if (!large) return fixed(t, tickDecimals(step));
    const [size, suffix] = UNITS.find(([unit]) => Math.abs(t) >= unit) ?? [1, ""];
    return compact(t, size, suffix, step);
  });
}
