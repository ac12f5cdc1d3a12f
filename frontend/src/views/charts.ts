/**
 * Small multiples (uPlot): one chart per charted demon, each with its own y-axis, the demon's prediction
 * (where the agent is) over the steps in its colour, and each evaluation like with like: at the step it
 * was made, a ring for the prediction from the state it was made from (the start, or the agent's state on a
 * world evaluated by rollouts) and a dark dot with its 95 % bar for the truth from that same state (exact on
 * a small lattice world, else the Monte-Carlo mean); the caption gives the latest pair. Evaluated again
 * later, the ring closes in on the dot as the demon learns. Classroom mode charts every demon (up to
 * MAX_MULTIPLES); otherwise the demons ticked in the table. Each chart is sized by its grid cell, never
 * by its content, so the page cannot grow sideways; the fonts follow "Large text". A demon whose values
 * span many powers of ten (`spansDecades`: a diverging one, as TD on Baird's star) is charted on a log
 * (asinh) scale, and its caption says so.
 */
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import { keys, watchQuery } from "../app/queries";
import { type App, type AppState, chartedDemons, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { api, unwrap } from "../api/client";
import type { Evaluation, History, Run } from "../api/types";
import { formatCount, formatNumber, nameParts } from "../lib/format";
import { type EvaluationMark, alignHistories, decadeTicks, markColumns, powerLabel, spansDecades } from "../lib/series";
import { h, replaceChildren, section, setText } from "../ui/dom";
import { lineLook, plotSize, remPx } from "./plots";

const REFRESH_MS = 1000;
const FALLBACK_COLOUR = "#0072B2";
const TRUTH_COLOUR = "#111827";

interface Multiple {
  demon: string;
  figure: HTMLElement;
  caption: HTMLElement;
  box: HTMLElement;
  plot: uPlot | null;
  /** what the plot was built for (colour, font size, scale): rebuilt when it changes */
  key: string;
}

/** Where an evaluation's prediction and truth are taken on this run's world, for the captions. */
function evaluatedFrom(run: Run | null): string {
  return run?.evaluation?.kind === "rollouts" ? "from the agent's state" : "from the start";
}

export function charts(app: App, scope: Scope): HTMLElement {
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
          : `Each chart has its own scale. Solid: the prediction where the agent is. Each Evaluate marks its step: a ring, the prediction ${evaluatedFrom(state.run)}, and a dark dot with its 95 % bar, the truth ${evaluatedFrom(state.run)}. Evaluate again later: the ring closes in on the dot as the demon learns.`,
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
    readAtStep = state(app).live?.step ?? null;
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
  // Every evaluation of the run shown, by demon, at the step the stream had reached when it came back.
  const marks = new Map<string, EvaluationMark[]>();
  let marked: { runId: string | null; evaluations: Record<string, Evaluation> } = { runId: null, evaluations: {} };
  const collectMarks = (state: Readonly<AppState>) => {
    if (state.selectedRunId !== marked.runId) marks.clear();
    for (const [demon, evaluation] of Object.entries(state.evaluations)) {
      const truth = truthLine(evaluation);
      if (evaluation === marked.evaluations[demon] || truth === null) continue;
      const step = state.live?.step ?? state.run?.step ?? 0;
      marks.set(demon, [...(marks.get(demon) ?? []), { step, prediction: evaluation.prediction, truth }]);
    }
    marked = { runId: state.selectedRunId, evaluations: state.evaluations };
  };
  collectMarks(state(app));

  // A demon removed or a run deleted between two reads fails a reading: the next one catches up.
  const histories = watchQuery(app.client, watchOf(state(app)), (read) => {
    for (const history of read) {
      const multiple = multiples.get(history.demon);
      if (multiple) draw(multiple, history, marks.get(history.demon) ?? [], state(app));
    }
  });

  watchState(
    app,
    scope,
    ["selectedRunId", "charted", "tab", "classroom", "demons", "evaluations", "large"],
    (state) => {
      collectMarks(state);
      layout(state);
      const watch = watchOf(state);
      histories.update(watch);
      if (watch.enabled) void histories.refetch();
    },
  );
  watchState(app, scope, ["live"], (state) => {
    const watch = watchOf(state);
    histories.update(watch);
    const step = state.live?.step ?? null;
    if (watch.enabled && state.live?.status !== "running" && step !== readAtStep) void histories.refetch();
  });
  layout(state(app));
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

/** The caption: the demon's name (broken only between its words) and the latest evaluation's pair. */
function caption(
  multiple: Multiple,
  latest: EvaluationMark | undefined,
  exact: boolean,
  state: Readonly<AppState>,
  log: boolean,
) {
  const [truth, , high] = latest?.truth ?? [];
  const pair =
    latest && truth !== undefined && high !== undefined
      ? ` · ${evaluatedFrom(state.run)} at step ${formatCount(latest.step)}: truth ${formatNumber(truth)}${exact ? " (exact)" : ` ± ${formatNumber(high - truth)}`}, prediction ${formatNumber(latest.prediction)}`
      : "";
  const name = nameParts(multiple.demon).flatMap((part, i) => (i === 0 ? [part] : [h("wbr", {}), part]));
  replaceChildren(
    multiple.caption,
    h("span", { class: "chart-name" }, name),
    pair + (log ? " · log scale: the values span many powers of ten" : ""),
  );
}

function draw(multiple: Multiple, history: History, marks: readonly EvaluationMark[], state: Readonly<AppState>): void {
  const demon = state.demons.find((d) => d.name === multiple.demon);
  const colour = demon?.colour ?? FALLBACK_COLOUR;
  const [steps, values] = alignHistories([history], "prediction") as [number[], (number | null)[]];
  const columns = markColumns(steps, marks);
  const data: uPlot.AlignedData = [steps, values, ...columns];
  // How many evaluations the chart shows (the browser tests read it: a canvas has no text to find).
  multiple.figure.dataset.marks = String(columns[0]?.filter((v) => v !== null).length ?? 0);
  const log = spansDecades([...values, ...columns.flat()]);
  caption(multiple, marks.at(-1), state.evaluations[multiple.demon]?.exact != null, state, log);
  multiple.caption.style.borderLeftColor = colour;
  const font = remPx();
  const key = `${colour}|${font}|${log}`;
  if (multiple.plot && multiple.key === key) {
    multiple.plot.setData(data);
    return;
  }
  multiple.plot?.destroy();
  multiple.key = key;
  const dot = (size: number, stroke: string, fill: string): uPlot.Series => ({
    stroke,
    width: 2,
    paths: () => null,
    points: { show: true, size, stroke, fill, width: 2 },
  });
  // The interval's ends count for the y range but are drawn as the truth's bar (whiskers), not as points.
  const end: uPlot.Series = { stroke: "transparent", paths: () => null, points: { show: false } };
  const series: uPlot.Series[] = [
    { label: "step" },
    { label: "prediction", stroke: colour, width: 2.5, spanGaps: false },
    { label: "evaluated: prediction", ...dot(Math.round(0.75 * font), colour, "#ffffff") },
    { label: "evaluated: truth", ...dot(Math.round(0.55 * font), TRUTH_COLOUR, TRUTH_COLOUR) },
    { label: "low", ...end },
    { label: "high", ...end },
  ];
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
      hooks: { draw: [...(look.hooks?.draw ?? []), drawTruthBars] },
    },
    data,
    multiple.box,
  );
}

/** The truth's 95 % bars: a vertical line from low to high at each evaluation's step. */
function drawTruthBars(u: uPlot): void {
  const [steps, , , , lows, highs] = u.data;
  if (!lows || !highs) return;
  const ctx = u.ctx;
  ctx.save();
  ctx.strokeStyle = TRUTH_COLOUR;
  ctx.lineWidth = 2 * devicePixelRatio;
  steps.forEach((step, i) => {
    const low = lows[i];
    const high = highs[i];
    if (low === null || low === undefined || high === null || high === undefined || low === high) return;
    const x = u.valToPos(step, "x", true);
    const cap = 4 * devicePixelRatio;
    ctx.beginPath();
    for (const value of [low, high]) {
      const y = u.valToPos(value, "y", true);
      ctx.moveTo(x - cap, y);
      ctx.lineTo(x + cap, y);
    }
    ctx.moveTo(x, u.valToPos(low, "y", true));
    ctx.lineTo(x, u.valToPos(high, "y", true));
    ctx.stroke();
  });
  ctx.restore();
}
