/**
 * A study's results in the Studies tab: (1) learning curves per configuration with 95 % bootstrap bands
 * over runs (the best ones, or those ticked in the table), (2) sensitivity curves of the final or mean error
 * against any swept axis, one curve per value of another, and (3) a sortable table of configurations with
 * the best marked. A configuration with a diverged run is flagged in the table and left out of the plots
 * (a note names it); the study's warnings stand above. `template` draws them from the server's latest answer.
 */
import { html } from "lit-html";
import { repeat } from "lit-html/directives/repeat.js";
import { formatNumber } from "../lib/format";
import { tip } from "../lib/glossary";
import {
  type AxisValue,
  type SortKey,
  type StudyConfig,
  type StudyDetail,
  bestConfigs,
  configLabel,
  defaultAxes,
  isNumericAxis,
  sensitivityCurves,
  shortPath,
  sortConfigs,
  splitDiverged,
  varyingAxes,
} from "../lib/study";
import { selectField } from "../ui/form";
import { choices } from "../ui/html";
import { bandChart } from "./study-chart";

const CURVES_SHOWN = 6;
const ERROR_HELP =
  "Error: root-mean-square error of each demon's prediction over every state against the exact answer " +
  "(Monte-Carlo truth at the start where no exact answer exists), divided by the size of that answer, " +
  "averaged over the demons. Bands and intervals: 95 % bootstrap over the runs. AUC: the mean error over " +
  "the learning curve (after episode 0), small when learning is fast.";

/** What the reader chose: the order of the table, the curves drawn, the sensitivity's axes and measure. */
export class StudyResults {
  sortKey: SortKey = "error";
  ascending = true;
  /** configuration indices on the learning-curve chart */
  shown = new Set<number>();
  /** until the user ticks or unticks one, the chart shows the best configurations */
  userChose = false;
  /** until the user picks, the sensitivity's axes follow the results as they come in */
  axes: { x: string; group: string; metric: "final" | "auc" } | null = null;
  private shownFor: string | null = null;

  constructor(private readonly changed: () => void) {}

  template(detail: StudyDetail) {
    if (this.shownFor !== detail.id) {
      this.shownFor = detail.id;
      this.userChose = false;
      this.axes = null;
    }
    const results = detail.results;
    const { kept, diverged } = splitDiverged(results);
    if (!this.userChose) this.shown = new Set(bestConfigs(kept, CURVES_SHOWN).map((c) => c.index));
    const warnings = detail.warnings ?? [];
    return html`<div class="study-results">
      <ul class="study-warnings" data-testid="study-warnings" ?hidden=${warnings.length === 0}>
        ${warnings.map((warning) => html`<li>${warning}</li>`)}
      </ul>
      <h4>Learning curves</h4>
      <p class="hint">Mean over runs with its 95 % bootstrap band; tick configurations in the table to draw them.</p>
      <div class="study-curves">${this.curves(kept)}</div>
      <p class="hint left-out" data-testid="left-out" ?hidden=${diverged.length === 0}>
        Left out of the plots, as a run of theirs diverged (their errors are no numbers to compare):
        ${diverged.map((c) => configLabel(c.axes)).join("; ")}.
      </p>
      <h4>Sensitivity</h4>
      ${this.sensitivity(results, kept)}
      <h4>Configurations</h4>
      <p class="hint">${ERROR_HELP}</p>
      <div class="study-table">${this.table(results)}</div>
    </div>`;
  }

  private curves(kept: StudyConfig[]) {
    const chosen = kept.filter((c) => this.shown.has(c.index));
    if (chosen.length === 0) return html`<p class="hint">No finished run yet.</p>`;
    return bandChart(
      chosen.map((c) => ({
        label: `${configLabel(c.axes)} (${c.runs} runs)`,
        x: c.episodes,
        ...c.curve,
        best: c.best,
      })),
      {
        title: "Relative error while learning",
        xLabel: "training episodes",
        yLabel: "relative error",
        logY: true,
        style: "band",
      },
    );
  }

  private sensitivity(results: StudyConfig[], kept: StudyConfig[]) {
    const paths = results.length > 0 ? Object.keys((results[0] as StudyConfig).axes) : [];
    const defaults = defaultAxes(results);
    const axes = this.axes ?? { x: defaults.x ?? "", group: defaults.group ?? "", metric: "final" as const };
    const choose = (key: "x" | "group" | "metric") => (event: Event) => {
      this.axes = { ...axes, [key]: (event.target as HTMLSelectElement).value };
      this.changed();
    };
    const pick = (label: string, id: string, key: "x" | "group" | "metric", items: (readonly [string, string])[]) =>
      selectField({ label, id }, { name: id, onChange: choose(key) }, choices(items, axes[key]));
    return html`<div class="row">
        ${pick(
          "Along",
          "sensitivity-x",
          "x",
          paths.map((p) => [p, p] as const),
        )}
        ${pick("One curve per", "sensitivity-group", "group", [["", "(none)"], ...paths.map((p) => [p, p] as const)])}
        ${pick("Measure", "sensitivity-metric", "metric", [
          ["final", "final error"],
          ["auc", "mean error over training (AUC)"],
        ])}
      </div>
      <div class="study-sensitivity">${sensitivityChart(kept, axes.x, axes.group || null, axes.metric)}</div>`;
  }

  private table(results: StudyConfig[]) {
    const paths = results.length > 0 ? Object.keys((results[0] as StudyConfig).axes) : [];
    const header = (label: string, key: SortKey) => {
      const sorted = this.sortKey === key;
      const sortBy = () => {
        this.ascending = sorted ? !this.ascending : true;
        this.sortKey = key;
        this.changed();
      };
      return html`<th scope="col" aria-sort=${sorted ? (this.ascending ? "ascending" : "descending") : "none"}>
        <button type="button" class="sort" @click=${sortBy}>
          ${label}${sorted ? (this.ascending ? " ▲" : " ▼") : ""}
        </button>
      </th>`;
    };
    return html`<table class="data-table study-configs">
      <thead>
        <tr>
          <th scope="col">draw</th>
          <th scope="col"></th>
          ${paths.map((p) => header(p, `axis:${p}`))}
          <th scope="col">runs</th>
          ${header("error", "error")}
          <th scope="col">95 % CI</th>
          ${header("AUC", "auc")}
        </tr>
      </thead>
      <tbody>
        ${repeat(
          sortConfigs(results, this.sortKey, this.ascending),
          (c) => c.index,
          (c) => this.row(c, paths),
        )}
      </tbody>
    </table>`;
  }

  private row(c: StudyConfig, paths: string[]) {
    const tick = (event: Event) => {
      this.userChose = true;
      if ((event.target as HTMLInputElement).checked) this.shown.add(c.index);
      else this.shown.delete(c.index);
      this.changed();
    };
    return html`<tr class=${c.best ? "best" : c.diverged ? "diverged" : ""} data-config=${String(c.index)}>
      <td>
        <input
          type="checkbox"
          .checked=${this.shown.has(c.index)}
          aria-label="Draw ${configLabel(c.axes)}"
          @change=${tick}
        />
      </td>
      <td>${c.best ? html`<strong title="the lowest final error">★ best</strong>` : ""}</td>
      ${paths.map((p) => html`<td class="num">${String(c.axes[p])}</td>`)}
      <td class="num">${String(c.runs)}</td>
      ${
        c.diverged
          ? html`<td class="num" colspan="3"><span class="tag diverged" title=${tip("diverged")}>diverged</span></td>`
          : html`<td class="num">${formatNumber(c.error, 4)}</td>
              <td class="num">${formatNumber(c.ci_low, 4)} – ${formatNumber(c.ci_high, 4)}</td>
              <td class="num">${formatNumber(c.auc, 4)}</td>`
      }
    </tr>`;
  }
}

/** The final (or mean) error against axis `x`, one curve per value of `group`, the best over the other axes. */
function sensitivityChart(results: StudyConfig[], x: string, group: string | null, which: "final" | "auc") {
  if (!x || varyingAxes(results).length === 0) {
    return html`<p class="hint">Sensitivity curves need an axis with two values or more.</p>`;
  }
  const numeric = isNumericAxis(results, x);
  const categories = numeric ? undefined : [...new Set(results.map((c) => String(c.axes[x])))].sort();
  const position = (v: AxisValue) => (numeric ? (v as number) : (categories as string[]).indexOf(String(v)));
  const values = results.map((c) => c.axes[x]).filter((v): v is number => typeof v === "number");
  const logX = numeric && values.every((v) => v > 0) && Math.max(...values) / Math.min(...values) >= 10;
  const others = Object.keys(results[0]?.axes ?? {}).filter((p) => p !== x && p !== group);
  return bandChart(
    sensitivityCurves(results, x, group, which).map((line) => ({
      label: group ? `${shortPath(group)}=${String(line.group)}` : "all",
      x: line.points.map((p) => position(p.x)),
      mean: line.points.map((p) => p.mean),
      low: line.points.map((p) => p.low),
      high: line.points.map((p) => p.high),
    })),
    {
      title:
        `${which === "final" ? "Final error" : "Mean error over training"} against ${x}` +
        (others.length ? ` (best over ${others.join(", ")})` : ""),
      xLabel: x,
      yLabel: which === "final" ? "final relative error" : "AUC",
      logX,
      logY: true,
      style: "bars",
      categories,
    },
  );
}
