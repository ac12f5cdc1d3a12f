/**
 * A study's results in the Studies tab: (1) learning curves per configuration with 95 % bootstrap bands
 * over runs (the best ones, or those ticked in the table), (2) sensitivity curves of the final or mean error
 * against any swept axis, one curve per value of another, and (3) a sortable table of configurations with
 * the best marked. A configuration with a diverged run is flagged in the table and left out of the plots
 * (a note names it); the study's warnings stand above. `show` redraws them from the server's latest answer.
 */
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
import { h, options, replaceChildren, setText } from "../ui/dom";
import { field } from "../ui/legacy-form";
import { bandChart } from "./study-chart";

const CURVES_SHOWN = 6;
const ERROR_HELP =
  "Error: root-mean-square error of each demon's prediction over every state against the exact answer " +
  "(Monte-Carlo truth at the start where no exact answer exists), divided by the size of that answer, " +
  "averaged over the demons. Bands and intervals: 95 % bootstrap over the runs. AUC: the mean error over " +
  "the learning curve (after episode 0), small when learning is fast.";

export interface StudyResults {
  element: HTMLElement;
  show(detail: StudyDetail): void;
}

export function studyResults(): StudyResults {
  let detail: StudyDetail | null = null;
  let sortKey: SortKey = "error";
  let ascending = true;
  let shown = new Set<number>(); // configuration indices on the learning-curve chart
  let userChose = false; // until the user ticks or unticks one, the chart shows the best configurations
  let shownFor: string | null = null;
  const curves = h("div", { class: "study-curves" });
  const sensitivity = h("div", { class: "study-sensitivity" });
  const xAxis = h("select", { name: "sensitivity-x", "aria-label": "Sensitivity: along" });
  const groupAxis = h("select", { name: "sensitivity-group", "aria-label": "Sensitivity: one curve per" });
  const metric = h(
    "select",
    { name: "sensitivity-metric", "aria-label": "Sensitivity: measure" },
    options([
      ["final", "final error"],
      ["auc", "mean error over training (AUC)"],
    ] as const),
  );
  let axesChosen = false;
  for (const select of [xAxis, groupAxis, metric])
    select.addEventListener("change", () => {
      axesChosen = true;
      drawSensitivity();
    });
  const table = h("div", { class: "study-table" });
  const warnings = h("ul", { class: "study-warnings", dataset: { testid: "study-warnings" } });
  const leftOut = h("p", { class: "hint left-out", dataset: { testid: "left-out" } });

  const show = (next: StudyDetail) => {
    detail = next;
    const results = next.results;
    if (shownFor !== next.id) {
      shownFor = next.id;
      userChose = false;
      axesChosen = false;
    }
    if (!axesChosen) {
      // until the user picks, the defaults follow the results as they come in
      const { x, group } = defaultAxes(results);
      fillAxisChoices(results, x, group);
    }
    if (!userChose) shown = new Set(bestConfigs(splitDiverged(results).kept, CURVES_SHOWN).map((c) => c.index));
    replaceChildren(
      warnings,
      (next.warnings ?? []).map((warning) => h("li", {}, warning)),
    );
    warnings.hidden = (next.warnings ?? []).length === 0;
    const { diverged } = splitDiverged(results);
    leftOut.hidden = diverged.length === 0;
    setText(
      leftOut,
      `Left out of the plots, as a run of theirs diverged (their errors are no numbers to compare): ${diverged.map((c) => configLabel(c.axes)).join("; ")}.`,
    );
    drawCurves();
    drawSensitivity();
    drawTable();
  };

  const fillAxisChoices = (results: StudyConfig[], x: string | null, group: string | null) => {
    const paths = results.length > 0 ? Object.keys((results[0] as StudyConfig).axes) : [];
    replaceChildren(xAxis, options(paths, x ?? undefined));
    replaceChildren(groupAxis, options([["", "(none)"], ...paths.map((p) => [p, p] as const)], group ?? ""));
  };

  const drawCurves = () => {
    if (!detail) return;
    const chosen = splitDiverged(detail.results).kept.filter((c) => shown.has(c.index));
    if (chosen.length === 0) {
      replaceChildren(curves, h("p", { class: "hint" }, "No finished run yet."));
      return;
    }
    replaceChildren(
      curves,
      bandChart(
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
      ),
    );
  };

  const drawSensitivity = () => {
    if (!detail) return;
    const results = splitDiverged(detail.results).kept;
    const x = xAxis.value;
    if (!x || varyingAxes(results).length === 0) {
      replaceChildren(
        sensitivity,
        h("p", { class: "hint" }, "Sensitivity curves need an axis with two values or more."),
      );
      return;
    }
    const group = groupAxis.value || null;
    const which = metric.value === "auc" ? "auc" : "final";
    const numeric = isNumericAxis(results, x);
    const categories = numeric ? undefined : [...new Set(results.map((c) => String(c.axes[x])))].sort();
    const position = (v: AxisValue) => (numeric ? (v as number) : (categories as string[]).indexOf(String(v)));
    const lines = sensitivityCurves(results, x, group, which);
    const values = results.map((c) => c.axes[x]).filter((v): v is number => typeof v === "number");
    const logX = numeric && values.every((v) => v > 0) && Math.max(...values) / Math.min(...values) >= 10;
    const others = Object.keys(results[0]?.axes ?? {}).filter((p) => p !== x && p !== group);
    replaceChildren(
      sensitivity,
      bandChart(
        lines.map((line) => ({
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
      ),
    );
  };

  const drawTable = () => {
    if (!detail) return;
    const results = detail.results;
    const paths = results.length > 0 ? Object.keys((results[0] as StudyConfig).axes) : [];
    const header = (label: string, key: SortKey) =>
      h(
        "th",
        { scope: "col", "aria-sort": sortKey === key ? (ascending ? "ascending" : "descending") : "none" },
        h(
          "button",
          {
            type: "button",
            class: "sort",
            onclick: () => {
              ascending = sortKey === key ? !ascending : true;
              sortKey = key;
              drawTable();
            },
          },
          label,
          sortKey === key ? (ascending ? " ▲" : " ▼") : "",
        ),
      );
    const rows = sortConfigs(results, sortKey, ascending).map((c) => {
      const tick = h("input", {
        type: "checkbox",
        checked: shown.has(c.index),
        "aria-label": `Draw ${configLabel(c.axes)}`,
      });
      tick.addEventListener("change", () => {
        userChose = true;
        if (tick.checked) shown.add(c.index);
        else shown.delete(c.index);
        drawCurves();
      });
      return h(
        "tr",
        { class: c.best ? "best" : c.diverged ? "diverged" : "", dataset: { config: String(c.index) } },
        h("td", {}, tick),
        h("td", {}, c.best ? h("strong", { title: "the lowest final error" }, "★ best") : ""),
        paths.map((p) => h("td", { class: "num" }, String(c.axes[p]))),
        h("td", { class: "num" }, String(c.runs)),
        ...(c.diverged
          ? [
              h(
                "td",
                { class: "num", colspan: 3 },
                h("span", { class: "tag diverged", title: tip("diverged") }, "diverged"),
              ),
            ]
          : [
              h("td", { class: "num" }, formatNumber(c.error, 4)),
              h("td", { class: "num" }, `${formatNumber(c.ci_low, 4)} – ${formatNumber(c.ci_high, 4)}`),
              h("td", { class: "num" }, formatNumber(c.auc, 4)),
            ]),
      );
    });
    replaceChildren(
      table,
      h(
        "table",
        { class: "data-table study-configs" },
        h(
          "thead",
          {},
          h(
            "tr",
            {},
            h("th", { scope: "col" }, "draw"),
            h("th", { scope: "col" }, ""),
            paths.map((p) => header(p, `axis:${p}`)),
            h("th", { scope: "col" }, "runs"),
            header("error", "error"),
            h("th", { scope: "col" }, "95 % CI"),
            header("AUC", "auc"),
          ),
        ),
        h("tbody", {}, rows),
      ),
    );
  };

  const element = h(
    "div",
    { class: "study-results" },
    warnings,
    h("h4", {}, "Learning curves"),
    h(
      "p",
      { class: "hint" },
      "Mean over runs with its 95 % bootstrap band; tick configurations in the table to draw them.",
    ),
    curves,
    leftOut,
    h("h4", {}, "Sensitivity"),
    h("div", { class: "row" }, field("Along", xAxis), field("One curve per", groupAxis), field("Measure", metric)),
    sensitivity,
    h("h4", {}, "Configurations"),
    h("p", { class: "hint" }, ERROR_HELP),
    table,
  );
  return { element, show };
}
