/**
 * Small multiples (uPlot): one chart per charted demon, each with its own y-axis, the demon's prediction
 * (where the agent is) over the steps in its colour, and, once evaluated, its truth from the start state
 * as a dashed line (exact on a small lattice world, else the Monte-Carlo mean with its 95 % band) with
 * the prediction there named beside it. Classroom mode charts every demon (up to
 * MAX_MULTIPLES); otherwise the demons ticked in the table. Each chart is sized by its grid cell, never
 * by its content, so the page cannot grow sideways; the fonts follow "Large text". A demon whose values
 * span many powers of ten (`spansDecades`: a diverging one, as TD on Baird's star) is charted on a log
 * (asinh) scale, and its caption says so.
 */
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import { keys, queryClient, watchQuery } from "../app/queries";
import { type AppState, type AppStore, chartedDemons } from "../app/state";
import { api, unwrap } from "../api/client";
import type { Evaluation, History } from "../api/types";
import { formatNumber } from "../lib/format";
import { alignHistories, decadeTicks, powerLabel, spansDecades } from "../lib/series";
import { h, replaceChildren, section, setText } from "../ui/dom";
import { lineLook, plotSize, remPx } from "./plots";

const REFRESH_MS = 1000;
const FALLBACK_COLOUR = "#0072B2";

interface Multiple {
  demon: string;
  figure: HTMLElement;
  caption: HTMLElement;
  box: HTMLElement;
  plot: uPlot | null;
  /** what the plot was built for (colour, truth, font size): rebuilt when it changes */
  key: string;
}

export function charts(store: AppStore): HTMLElement {
  const note = h("p", { class: "muted" });
  const grid = h("div", { class: "chart-grid" });
  const element = section(
    { class: "panel charts-panel", id: "charts-title", title: "Predictions over time" },
    note,
    grid,
  );
  const multiples = new Map<string, Multiple>();

  const layout = (state: Readonly<AppState>) => {
    const names = chartedDemons(state);
    const all = state.classroom ? state.demons.length : names.length;
    setText(
      note,
      names.length === 0
        ? "Tick “chart” under a demon’s name in the table, or switch on classroom mode, to follow it here."
        : all > names.length
          ? `The first ${names.length} of ${all} demons; pick others with “chart” in the table.`
          : "Each chart has its own scale. Solid: the prediction where the agent is. Dashed, once evaluated: the truth from the start (exact, or Monte-Carlo with its 95 % band), and the caption gives the prediction there.",
    );
    for (const [name, multiple] of multiples) {
      if (!names.includes(name)) {
        multiple.plot?.destroy();
        multiples.delete(name);
      }
    }
    const figures = names.map((name) => {
      let multiple = multiples.get(name);
      if (!multiple) {
        const caption = h("figcaption", {});
        const box = h("div", { class: "chart-box" });
        multiple = {
          demon: name,
          figure: h("figure", { class: "chart", dataset: { demon: name } }, caption, box),
          caption,
          box,
          plot: null,
          key: "",
        };
        multiples.set(name, multiple);
      }
      return multiple.figure;
    });
    // Only when the set changed: re-adding figures would reset their plots' sizes for nothing.
    const order = names.join("\u0000");
    if (grid.dataset.order !== order) {
      grid.dataset.order = order;
      replaceChildren(grid, figures);
    }
  };

  // The charted demons' histories: a query read every second while the run runs, at once when the
  // choice, the run or an evaluation changes, and after a step of a paused run.
  let readAtStep: number | null = null;
  const readHistories = async (runId: string, names: readonly string[]): Promise<History[]> => {
    readAtStep = store.state.live?.step ?? null;
    return Promise.all(
      names.map((name) =>
        unwrap(api.GET("/api/runs/{run_id}/demons/{name}/history", { params: { path: { run_id: runId, name } } })),
      ),
    );
  };
  const watchOf = (state: Readonly<AppState>) => {
    const runId = state.selectedRunId ?? "";
    const names = chartedDemons(state);
    return {
      queryKey: keys.histories(runId, names),
      queryFn: () => readHistories(runId, names),
      every: state.live?.status === "running" ? REFRESH_MS : (false as const),
      enabled: runId !== "" && names.length > 0 && state.tab === "live",
    };
  };
  // A demon removed or a run deleted between two reads fails a reading: the next one catches up.
  const histories = watchQuery(queryClient, watchOf(store.state), (read) => {
    for (const history of read) {
      const multiple = multiples.get(history.demon);
      if (multiple) draw(multiple, history, store.state);
    }
  });

  store.subscribe(
    (state) => {
      layout(state);
      const watch = watchOf(state);
      histories.update(watch);
      if (watch.enabled) void histories.refetch();
    },
    ["selectedRunId", "charted", "tab", "classroom", "demons", "evaluations", "large"],
  );
  store.subscribe(
    (state) => {
      const watch = watchOf(state);
      histories.update(watch);
      const step = state.live?.step ?? null;
      if (watch.enabled && state.live?.status !== "running" && step !== readAtStep) void histories.refetch();
    },
    ["live"],
  );
  layout(store.state);
  // The grid decides each cell's width; the plots follow it (and never the other way round).
  new ResizeObserver(() => {
    for (const multiple of multiples.values()) multiple.plot?.setSize(chartSize(multiple.box));
  }).observe(grid);
  return element;
}

/** A chart cell's plot: as wide as its cell, 0.55 of that high, at least 9 rem. */
const chartSize = (box: HTMLElement) => plotSize(box, 9, 0.55);

/** The truth to draw: [value, low, high] (low = high = value when exact), or null before an evaluation. */
export function truthLine(evaluation: Evaluation | undefined): [number, number, number] | null {
  if (!evaluation) return null;
  if (evaluation.exact !== null && evaluation.exact !== undefined) {
    return [evaluation.exact, evaluation.exact, evaluation.exact];
  }
  if (evaluation.truth === null || evaluation.truth === undefined) return null;
  const half = 1.96 * (evaluation.stderr ?? 0);
  return [evaluation.truth, evaluation.truth - half, evaluation.truth + half];
}

function draw(multiple: Multiple, history: History, state: Readonly<AppState>): void {
  const demon = state.demons.find((d) => d.name === multiple.demon);
  const colour = demon?.colour ?? FALLBACK_COLOUR;
  const evaluation = state.evaluations[multiple.demon];
  const truth = truthLine(evaluation);
  const [steps, values] = alignHistories([history], "prediction") as [number[], (number | null)[]];
  const data: uPlot.AlignedData = truth
    ? [steps, values, steps.map(() => truth[0]), steps.map(() => truth[1]), steps.map(() => truth[2])]
    : [steps, values];
  const log = spansDecades(values);
  setText(
    multiple.caption,
    (truth && evaluation
      ? `${multiple.demon} · at the start: truth ${formatNumber(truth[0])}${evaluation.exact != null ? " (exact)" : ` ± ${formatNumber(truth[2] - truth[0])}`}, prediction ${formatNumber(evaluation.prediction)}`
      : multiple.demon) + (log ? " · log scale: the values span many powers of ten" : ""),
  );
  multiple.caption.style.borderLeftColor = colour;
  const font = remPx();
  const key = `${colour}|${truth?.join(",") ?? ""}|${font}|${log}`;
  if (multiple.plot && multiple.key === key) {
    multiple.plot.setData(data);
    return;
  }
  multiple.plot?.destroy();
  multiple.key = key;
  const series: uPlot.Series[] = [
    { label: "step" },
    { label: "prediction", stroke: colour, width: 2.5, spanGaps: false },
  ];
  if (truth) {
    series.push(
      { label: "truth", stroke: "#111827", width: 2, dash: [8, 6] },
      { label: "low", stroke: "transparent", width: 0, show: true },
      { label: "high", stroke: "transparent", width: 0, show: true },
    );
  }
  const look = lineLook("step");
  if (log) {
    look.scales = { ...look.scales, y: { distr: 4, asinh: 1 } }; // linear within ±1, log beyond
    const [xAxis, yAxis] = look.axes ?? [];
    look.axes = [
      xAxis ?? {},
      {
        ...yAxis,
        space: 16, // a few powers of ten, each label a line apart
        splits: (_u, _a, min, max) => decadeTicks(min, max),
        values: (_u, ticks) => ticks.map(powerLabel),
      },
    ];
  }
  multiple.plot = new uPlot(
    {
      ...chartSize(multiple.box),
      ...look,
      title: undefined,
      series,
      bands: truth ? [{ series: [4, 3], fill: "rgba(17, 24, 39, 0.12)" }] : [],
    },
    data,
    multiple.box,
  );
}
