/** The strip chart of a stream run (views/stream-runs.ts): one uPlot plot per chosen sensor and demon. */
import { html } from "lit-html";
import { ifDefined } from "lit-html/directives/if-defined.js";
import { ref } from "lit-html/directives/ref.js";
import { styleMap } from "lit-html/directives/style-map.js";
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import type { App } from "../app/app";
import type { StreamHistory } from "../api/types";
import { formatCount, formatNumber } from "../lib/format";
import { type Columns, demonColumns, sensorColumns, stripError } from "../lib/stream-history";
import type { Scope } from "../ui/scope";
import { lineLook, plotSize } from "./plots";

const PREDICTION = "#0072B2";
const RETURN = "#111827";
const SENSOR = "#009E73";

/** The stream run shown, what is drawn of it, and its plots. */
export interface Strip {
  app: App;
  scope: Scope;
  selected: string | null;
  sensors: string[];
  demons: string[];
  plots: Map<string, StripPlot>;
  draw: () => void;
  /** draw, and read what is now chosen */
  follow?: () => void;
}

/** One sensor's or demon's plot. */
export interface StripPlot {
  kind: "sensor" | "demon";
  name: string;
  /** its plot's life: released when it is no longer chosen */
  scope: Scope;
  box?: HTMLElement;
  plot: uPlot | null;
  caption: string;
}

/** The plot of `key` ("sensor:NAME" or "demon:NAME"), made on first use. */
export function stripPlotOf(strip: Strip, key: string): StripPlot {
  let plot = strip.plots.get(key);
  if (plot) return plot;
  const kind = key.startsWith("sensor:") ? "sensor" : "demon";
  const made: StripPlot = {
    kind,
    name: key.slice(kind.length + 1),
    scope: strip.scope.child(),
    plot: null,
    caption: "",
  };
  made.caption = made.name;
  made.scope.add(() => made.plot?.destroy());
  strip.plots.set(key, (plot = made));
  return plot;
}

/** The plots follow their cells' widths (never the other way round). */
export function resizeStrip(strip: Strip): void {
  for (const plot of strip.plots.values()) if (plot.plot && plot.box) plot.plot.setSize(stripSize(plot.box));
}

export function stripFigure(plot: StripPlot) {
  const sensor = plot.kind === "sensor" ? plot.name : undefined;
  const demon = plot.kind === "demon" ? plot.name : undefined;
  return html`<figure class="chart" data-sensor=${ifDefined(sensor)} data-demon=${ifDefined(demon)}>
    <figcaption style=${styleMap({ borderLeftColor: plot.kind === "sensor" ? SENSOR : PREDICTION })}>
      ${plot.caption}
    </figcaption>
    <div class="chart-box" ${ref((box) => (plot.box = box as HTMLElement | undefined))}></div>
  </figure>`;
}

/** A new reading of the strip's history: each plot's data, each demon's caption. */
export function drawStrip(strip: Strip, read: StreamHistory): void {
  for (const plot of strip.plots.values()) {
    if (!plot.box) continue;
    if (plot.kind === "sensor") {
      draw(plot, sensorColumns(read, plot.name), [{ label: plot.name, stroke: SENSOR, width: 2 }]);
      continue;
    }
    const name = plot.name;
    const error = stripError(read, name);
    plot.caption =
      read.returns[name] === null
        ? `${name} · its question reads other demons' predictions: no realised return`
        : error.count > 0
          ? `${name} · mean |prediction − return| ${formatNumber(error.meanAbsolute)} over ${formatCount(error.count)} records`
          : `${name} · no realised return known yet`;
    draw(plot, demonColumns(read, name), [
      { label: "prediction", stroke: PREDICTION, width: 2 },
      { label: "realised return", stroke: RETURN, width: 1.5, dash: [6, 4] },
    ]);
  }
  strip.draw(); // the captions
}

/** A strip plot: as wide as its cell, 0.6 of that high, at least 10 rem. */
const stripSize = (box: HTMLElement) => plotSize(box, 10, 0.6);

function draw(plot: StripPlot, columns: Columns, series: uPlot.Series[]): void {
  const data = columns as unknown as uPlot.AlignedData;
  if (columns[0].length < 2 || !plot.box) return; // uPlot keeps a broken x range when it starts with fewer than two points
  if (plot.plot) {
    plot.plot.setData(data);
    return;
  }
  plot.plot = new uPlot(
    {
      ...stripSize(plot.box),
      ...lineLook("record"),
      series: [{ label: "record" }, ...series.map((s) => ({ ...s, spanGaps: false }))],
    },
    data,
    plot.box,
  );
}
