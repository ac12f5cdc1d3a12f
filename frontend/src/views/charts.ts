/**
 * Time-series charts (uPlot) of the charted demons: prediction and RUPEE against the step, read from
 * GET /api/runs/{id}/demons/{name}/history about once a second while the run moves.
 */
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import type { AppStore } from "../app/state";
import { api, unwrap } from "../api/client";
import type { History } from "../api/types";
import { type ChartData, type Metric, alignHistories } from "../lib/series";
import { h } from "../ui/dom";

const REFRESH_MS = 1000;
const HEIGHT = 180;
// Distinguishable on a projector and for the common colour-vision deficiencies (Okabe-Ito).
const PALETTE = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000"];

interface Chart {
  metric: Metric;
  box: HTMLElement;
  plot: uPlot | null;
  series: string;
}

export function charts(store: AppStore): HTMLElement {
  const note = h("p", { class: "muted" }, "Tick “chart” under a demon’s name in the table to follow it here.");
  const list: Chart[] = (
    [
      ["prediction", "Prediction"],
      ["rupee", "RUPEE"],
    ] as const
  ).map(([metric, title]) => ({
    metric,
    box: h("figure", { class: "chart", "aria-label": `${title} over steps` }, h("figcaption", {}, title)),
    plot: null,
    series: "",
  }));
  const element = h(
    "section",
    { class: "panel charts-panel", "aria-labelledby": "charts-title" },
    h("h2", { id: "charts-title" }, "Over time"),
    note,
    list.map((c) => c.box),
  );

  let lastKey = "";
  let busy = false;

  const refresh = async (force = false) => {
    const { selectedRunId: runId, charted, live, tab } = store.state;
    note.hidden = charted.length > 0;
    if (runId === null || charted.length === 0 || tab !== "live" || document.hidden) {
      if (charted.length === 0) for (const chart of list) destroy(chart);
      return;
    }
    // Nothing new to read while the run stands still.
    const key = `${runId}|${charted.join(",")}|${live?.step ?? ""}`;
    if ((!force && key === lastKey) || busy) return;
    busy = true;
    try {
      const histories = await Promise.all(
        charted.map((name) =>
          unwrap(api.GET("/api/runs/{run_id}/demons/{name}/history", { params: { path: { run_id: runId, name } } })),
        ),
      );
      if (store.state.selectedRunId !== runId) return;
      lastKey = key;
      for (const chart of list) draw(chart, histories);
    } catch {
      // A demon removed or a run deleted between two reads: the next refresh catches up.
    } finally {
      busy = false;
    }
  };

  store.subscribe(() => void refresh(true), ["selectedRunId", "charted", "tab"]);
  window.setInterval(() => void refresh(), REFRESH_MS);
  new ResizeObserver(() => {
    for (const chart of list) chart.plot?.setSize({ width: chartWidth(chart.box), height: HEIGHT });
  }).observe(element);
  return element;
}

function chartWidth(box: HTMLElement): number {
  return Math.max(240, box.clientWidth - 4);
}

function destroy(chart: Chart): void {
  chart.plot?.destroy();
  chart.plot = null;
  chart.series = "";
}

function draw(chart: Chart, histories: History[]): void {
  const data: ChartData = alignHistories(histories, chart.metric);
  const names = histories.map((h) => h.demon).join(",");
  if (chart.plot && chart.series === names) {
    chart.plot.setData(data as uPlot.AlignedData);
    return;
  }
  destroy(chart);
  chart.series = names;
  chart.plot = new uPlot(
    {
      width: chartWidth(chart.box),
      height: HEIGHT,
      legend: { show: true, live: false }, // names only: the values under the cursor would jump at 1 Hz
      scales: { x: { time: false } },
      axes: [
        {
          label: "step",
          stroke: "#111827",
          grid: { stroke: "#e5e7eb" },
          font: "14px system-ui",
          labelFont: "bold 14px system-ui",
        },
        { stroke: "#111827", grid: { stroke: "#e5e7eb" }, font: "14px system-ui", size: 70 },
      ],
      series: [
        { label: "step" },
        ...histories.map((h, i) => ({
          label: h.demon,
          stroke: PALETTE[i % PALETTE.length],
          width: 2.5,
          spanGaps: false,
        })),
      ],
    },
    data as uPlot.AlignedData,
    chart.box,
  );
}
