/**
 * RMSVE and RMSPBE, the online errors a run records in its history on a world of discrete states with known
 * transitions (the chains, Baird's star; `horde.worlds.state_values.StateErrors` on the server): the demon
 * table shows each demon's latest beside RUPEE. Elsewhere the history has none (null, not 0).
 */
import type { History } from "../api/types";

/** A demon's latest RMSVE and RMSPBE (null: no truth for it, or not measured yet). */
export interface StateErrors {
  rmsve: number | null;
  rmspbe: number | null;
}

/** The table reads them for at most this many demons (one short history request each); chain runs have a few. */
export const MAX_ERROR_DEMONS = 50;

/** Each demon's errors at its history's last row; null when the run records none (no discrete states). */
export function latestErrors(histories: readonly History[]): Map<string, StateErrors> | null {
  if (histories.every((h) => h.rmsve === null || h.rmsve === undefined)) return null;
  return new Map(histories.map((h) => [h.demon, { rmsve: h.rmsve?.at(-1) ?? null, rmspbe: h.rmspbe?.at(-1) ?? null }]));
}
