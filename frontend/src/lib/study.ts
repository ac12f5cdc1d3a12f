/**
 * Studies in the dashboard, the pure part: reading axis values typed by a person, naming configurations,
 * sorting the table, and the points of sensitivity curves (the best configuration over the axes that are
 * neither on the x axis nor the grouping one), as `horde study --plots` draws them.
 */
import type { Band, Study, StudyConfig, StudyDetail, StudyIn } from "../api/types";
import { formatCountOf } from "./format";

export type { Band, Study, StudyConfig, StudyDetail, StudyIn };
export type AxisValue = number | string | boolean;

/** "0.01, 0.1, 1" -> numbers; "td, gq" -> strings; true/false -> booleans. Empty items are dropped. */
export function parseValues(text: string): AxisValue[] {
  return text
    .split(",")
    .map((item) => item.trim())
    .filter((item) => item.length > 0)
    .map((item) => {
      if (item === "true" || item === "false") return item === "true";
      const number = Number(item);
      return Number.isFinite(number) && /^[-+0-9.eE]+$/.test(item) ? number : item.replace(/^["']|["']$/g, "");
    });
}

/** The last part of an axis path: "learning.alpha" -> "alpha", "demons.*.learner" -> "learner". */
export function shortPath(path: string): string {
  return path.split(".").pop() ?? path;
}

export function formatValue(value: AxisValue): string {
  return typeof value === "number" ? String(value) : String(value);
}

/** "alpha=0.1 learner=td" */
export function configLabel(axes: Record<string, AxisValue>): string {
  const parts = Object.entries(axes).map(([path, value]) => `${shortPath(path)}=${formatValue(value)}`);
  return parts.length > 0 ? parts.join(" ") : "the base";
}

export type SortKey = "error" | "auc" | `axis:${string}`;

/** Configurations sorted by a column (numbers before missing ones; axis values numerically or by name). */
export function sortConfigs(configs: readonly StudyConfig[], key: SortKey, ascending = true): StudyConfig[] {
  const value = (c: StudyConfig): number | string | null => {
    if (key === "error") return c.error ?? null;
    if (key === "auc") return c.auc ?? null;
    const v = c.axes[key.slice(5)];
    return v === undefined ? null : typeof v === "boolean" ? String(v) : v;
  };
  const sign = ascending ? 1 : -1;
  return [...configs].sort((a, b) => {
    const x = value(a);
    const y = value(b);
    if (x === null || y === null) return x === null ? (y === null ? 0 : 1) : -1;
    if (typeof x === "number" && typeof y === "number") return sign * (x - y);
    return sign * String(x).localeCompare(String(y));
  });
}

export function isNumericAxis(configs: readonly StudyConfig[], path: string): boolean {
  return configs.every((c) => typeof c.axes[path] === "number");
}

/** The axes that take more than one value among the configurations. */
export function varyingAxes(configs: readonly StudyConfig[]): string[] {
  const paths = configs.length > 0 ? Object.keys((configs[0] as StudyConfig).axes) : [];
  return paths.filter((p) => new Set(configs.map((c) => JSON.stringify(c.axes[p]))).size > 1);
}

/** Default sensitivity axes: x the first numeric varying axis, group the last other varying one. */
export function defaultAxes(configs: readonly StudyConfig[]): { x: string | null; group: string | null } {
  const varying = varyingAxes(configs);
  const x = varying.find((p) => isNumericAxis(configs, p)) ?? varying[0] ?? null;
  const group = [...varying].reverse().find((p) => p !== x) ?? null;
  return { x, group };
}

export interface SensitivityPoint {
  x: AxisValue;
  mean: number;
  low: number;
  high: number;
  config: StudyConfig;
}

export interface SensitivityCurve {
  group: AxisValue | null;
  points: SensitivityPoint[];
}

/** One curve per value of `group`: for each x value, the configuration with the lowest `metric`. */
export function sensitivityCurves(
  configs: readonly StudyConfig[],
  x: string,
  group: string | null,
  metric: "final" | "auc",
): SensitivityCurve[] {
  const pick = (c: StudyConfig) =>
    metric === "final" ? ([c.error, c.ci_low, c.ci_high] as const) : ([c.auc, c.auc_low, c.auc_high] as const);
  const best = new Map<string, Map<string, StudyConfig>>();
  for (const config of configs) {
    const [mean] = pick(config);
    if (mean === null || mean === undefined) continue;
    const g = group === null ? "" : JSON.stringify(config.axes[group]);
    const xv = JSON.stringify(config.axes[x]);
    const row = best.get(g) ?? new Map<string, StudyConfig>();
    const current = row.get(xv);
    if (!current || (pick(current)[0] as number) > mean) row.set(xv, config);
    best.set(g, row);
  }
  const numeric = isNumericAxis(configs, x);
  return [...best.entries()].map(([g, row]) => ({
    group: g === "" ? null : (JSON.parse(g) as AxisValue),
    points: [...row.values()]
      .map((config) => {
        const [mean, low, high] = pick(config);
        return {
          x: config.axes[x] as AxisValue,
          mean: mean as number,
          low: low ?? (mean as number),
          high: high ?? (mean as number),
          config,
        };
      })
      .sort((a, b) => (numeric ? (a.x as number) - (b.x as number) : String(a.x).localeCompare(String(b.x)))),
  }));
}

/**
 * The configurations the plots draw, and those they leave out because a run of theirs diverged: their
 * numbers (errors of 10^9, intervals over nine powers of ten) are no errors to compare and would stretch
 * every axis. A server that does not say `diverged` leaves every configuration in.
 */
export function splitDiverged(configs: readonly StudyConfig[]): { kept: StudyConfig[]; diverged: StudyConfig[] } {
  return {
    kept: configs.filter((c) => !c.diverged),
    diverged: configs.filter((c) => c.diverged === true),
  };
}

/** At most `limit` configurations for the learning-curve chart: the best ones, best first. */
export function bestConfigs(configs: readonly StudyConfig[], limit: number): StudyConfig[] {
  return sortConfigs(configs, "error").slice(0, limit);
}

/** A study's size: "4 configurations x 1 run". */
export function studySize(study: Pick<Study, "configurations" | "runs">): string {
  return `${formatCountOf(study.configurations, "configuration")} x ${formatCountOf(study.runs, "run")}`;
}

/** "12 of 40 tasks" and "about 1 min left" for a study's progress. */
export function studyProgress(study: Study): { fraction: number; counted: string; left: string } {
  const fraction = study.tasks > 0 ? study.tasks_done / study.tasks : 0;
  const seconds = study.seconds_left;
  let left = "";
  if (study.status === "running" && seconds !== null && seconds !== undefined) {
    left =
      seconds < 90 ? `about ${Math.max(1, Math.round(seconds))} s left` : `about ${Math.round(seconds / 60)} min left`;
  }
  return { fraction, counted: `${study.tasks_done} of ${study.tasks} tasks`, left };
}
