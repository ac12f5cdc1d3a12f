/** The demon table's filter and summary, over thousands of demons at 30 updates a second. */
import type { Demon, DemonMetrics } from "../api/types";

export interface DemonFilter {
  /** words that must all appear in the demon's name or its question */
  text: string;
  show: "all" | "learning" | "diverged" | "charted" | "control";
}

export interface DemonSummary {
  demons: number;
  learning: number;
  diverged: number;
  /** the mean RUPEE over the demons that learn and have one */
  meanRupee: number | null;
}

function diverged(demon: Demon, metrics: Readonly<Record<string, DemonMetrics>>): boolean {
  return (metrics[demon.name] ?? demon.metrics).diverged;
}

// The searchable text of a demon, made once per demon object (the table filters 30 times a second).
const searchText = new WeakMap<Demon, string>();

function textOf(demon: Demon): string {
  let text = searchText.get(demon);
  if (text === undefined) {
    text = `${demon.name} ${JSON.stringify(demon.spec)}`.toLowerCase();
    searchText.set(demon, text);
  }
  return text;
}

export function filterDemons(
  demons: readonly Demon[],
  filter: DemonFilter,
  metrics: Readonly<Record<string, DemonMetrics>>,
  charted: readonly string[],
): Demon[] {
  const words = filter.text.toLowerCase().split(/\s+/).filter(Boolean);
  const chartedSet = new Set(charted);
  return demons.filter((demon) => {
    if (filter.show === "learning" && diverged(demon, metrics)) return false;
    if (filter.show === "diverged" && !diverged(demon, metrics)) return false;
    if (filter.show === "charted" && !chartedSet.has(demon.name)) return false;
    if (filter.show === "control" && !demon.control) return false;
    if (words.length === 0) return true;
    const text = textOf(demon);
    return words.every((word) => text.includes(word));
  });
}

export function demonSummary(demons: readonly Demon[], metrics: Readonly<Record<string, DemonMetrics>>): DemonSummary {
  let divergedCount = 0;
  let sum = 0;
  let counted = 0;
  for (const demon of demons) {
    const m = metrics[demon.name] ?? demon.metrics;
    if (m.diverged) divergedCount += 1;
    else if (m.rupee !== null && m.rupee !== undefined && Number.isFinite(m.rupee)) {
      sum += m.rupee;
      counted += 1;
    }
  }
  return {
    demons: demons.length,
    learning: demons.length - divergedCount,
    diverged: divergedCount,
    meanRupee: counted > 0 ? sum / counted : null,
  };
}

/** sign(v) log10(1 + |v|), then scaled into [-1, 1] by the largest magnitude (0 when none). */
/** For the overview of all predictions: */
export function overviewLevels(values: readonly (number | null | undefined)[]): number[] {
  const logs = values.map((v) =>
    v === null || v === undefined || !Number.isFinite(v) ? NaN : Math.sign(v) * Math.log10(1 + Math.abs(v)),
  );
  const largest = Math.max(0, ...logs.filter((v) => !Number.isNaN(v)).map(Math.abs));
  return logs.map((v) => (Number.isNaN(v) ? NaN : largest > 0 ? v / largest : 0));
}
