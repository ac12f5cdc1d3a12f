/**
 * Every protocol job the server keeps, as one sortable table beside the thesis's numbers; and groups of
 * scenarios run one after another (all of Experiment 2 in one click). Pure functions, tested without a
 * browser.
 */
import type { Protocol } from "../api/types";

/** A group of scenarios that share the part of their name before the first "-" ("experiment2-whole"). */
export interface ScenarioGroup {
  key: string;
  label: string;
  scenarios: string[];
}

/** The groups of two or more scenarios, in the order of their first member. */
export function scenarioGroups(names: readonly string[]): ScenarioGroup[] {
  const groups = new Map<string, string[]>();
  for (const name of names) {
    const key = name.split("-")[0] ?? name;
    groups.set(key, [...(groups.get(key) ?? []), name]);
  }
  return [...groups.entries()]
    .filter(([, members]) => members.length > 1)
    .map(([key, scenarios]) => ({
      key,
      label: `all of ${key} (${scenarios.length} scenarios, one after another)`,
      scenarios,
    }));
}

export interface JobRow {
  /** job id + demon: unique */
  key: string;
  job: string;
  scenario: string;
  demon: string;
  /** null when the demon diverged */
  prediction: number | null;
  truth: number | null;
  stderr: number | null;
  error: number | null;
  thesis: number | null;
  /** prediction - thesis */
  offThesis: number | null;
  trials: number;
  episodes: number;
  finished: string;
}

/** One row per demon of every finished job that has results, newest job first. */
export function jobRows(jobs: readonly Protocol[], thesisOnly: boolean): JobRow[] {
  const rows: JobRow[] = [];
  for (const job of [...jobs].reverse()) {
    for (const result of job.results ?? []) {
      const thesis = result.thesis ?? null;
      if (thesisOnly && thesis === null) continue;
      rows.push({
        key: `${job.id}/${result.name}`,
        job: job.id,
        scenario: job.name ?? "",
        demon: result.name,
        prediction: result.prediction ?? null,
        truth: result.truth ?? null,
        stderr: result.truth_stderr ?? null,
        error: result.error ?? null,
        thesis,
        offThesis: thesis === null || result.prediction == null ? null : result.prediction - thesis,
        trials: job.trials,
        episodes: job.episodes,
        finished: job.finished_at ?? "",
      });
    }
  }
  return rows;
}

export type SortKey = "scenario" | "demon" | "prediction" | "truth" | "error" | "thesis" | "offThesis" | "finished";

/** Rows sorted by one column; missing numbers last either way; ties keep their order. */
export function sortRows(rows: readonly JobRow[], key: SortKey, ascending: boolean): JobRow[] {
  const sign = ascending ? 1 : -1;
  return rows
    .map((row, i) => ({ row, i }))
    .sort((a, b) => {
      const x = a.row[key];
      const y = b.row[key];
      if (x === null || y === null) return x === y ? a.i - b.i : x === null ? 1 : -1;
      const order = typeof x === "number" && typeof y === "number" ? x - y : String(x).localeCompare(String(y));
      return order === 0 ? a.i - b.i : sign * order;
    })
    .map(({ row }) => row);
}
