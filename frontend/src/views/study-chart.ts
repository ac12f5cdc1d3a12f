/**
 * A small SVG chart of means with 95 % bands: learning curves (a line and a shaded band per series) and
 * sensitivity curves (points with error bars joined by lines). Log scales where asked, a legend of
 * the series below, and a title that says what is drawn. Pure drawing (lit-html SVG templates): no state, no requests.
 */
import { html, nothing, svg } from "lit-html";
import { styleMap } from "lit-html/directives/style-map.js";

export interface ChartSeries {
  label: string;
  x: number[];
  mean: (number | null)[];
  low: (number | null)[];
  high: (number | null)[];
  best?: boolean;
}

export interface ChartOptions {
  title: string;
  xLabel: string;
  yLabel: string;
  logX?: boolean;
  logY?: boolean;
  /** "band": shaded band per series (learning curves); "bars": error bars at the points (sensitivity) */
  style: "band" | "bars";
  /** names of the x positions 0, 1, 2... when the axis is not numeric */
  categories?: string[];
}

export const PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf"];
const W = 560;
const H = 300;
const M = { left: 62, right: 14, top: 12, bottom: 42 };

type Scale = (v: number) => number;
let chartCount = 0; // ids of clip paths, unique in the document

function extent(values: number[], log: boolean): [number, number] {
  const usable = values.filter((v) => Number.isFinite(v) && (!log || v > 0));
  if (usable.length === 0) return log ? [0.1, 1] : [0, 1];
  let lo = Math.min(...usable);
  let hi = Math.max(...usable);
  if (lo === hi) {
    lo = log ? lo / 2 : lo - 1;
    hi = log ? hi * 2 : hi + 1;
  }
  return [lo, hi];
}

function scale(lo: number, hi: number, from: number, to: number, log: boolean): Scale {
  const f = (v: number) => (log ? Math.log10(v) : v);
  const a = f(lo);
  const b = f(hi);
  return (v: number) => from + ((f(v) - a) / (b - a || 1)) * (to - from);
}

/** Tick positions: decades on a log axis, about five round numbers on a linear one. */
export function ticks(lo: number, hi: number, log: boolean): number[] {
  if (log) {
    // 1, 2, 5 x 10^k inside the range; only the powers of ten when that makes too many
    const out: number[] = [];
    for (let e = Math.floor(Math.log10(lo)); e <= Math.ceil(Math.log10(hi)); e += 1) {
      for (const m of [1, 2, 5]) {
        const v = m * 10 ** e;
        if (v >= lo * 0.999 && v <= hi * 1.001) out.push(Number(v.toPrecision(6)));
      }
    }
    const decades = out.filter((v) => Math.abs(Math.log10(v) - Math.round(Math.log10(v))) < 1e-9);
    if (out.length > 8 && decades.length >= 2) return decades;
    return out.length >= 3 ? out : ticks(lo, hi, false);
  }
  const step0 = (hi - lo) / 5;
  const power = 10 ** Math.floor(Math.log10(step0));
  const step = [1, 2, 5, 10].map((m) => m * power).find((m) => m >= step0) ?? step0;
  const out: number[] = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(Number(v.toPrecision(12)));
  return out;
}

function tickLabel(v: number): string {
  if (v === 0) return "0";
  const a = Math.abs(v);
  return a >= 1e4 || a < 1e-3 ? v.toExponential(0) : String(Number(v.toPrecision(3)));
}

function pathOf(points: [number, number][]): string {
  return points.map(([x, y], i) => `${i ? "L" : "M"}${x.toFixed(1)},${y.toFixed(1)}`).join("");
}

/** The chart's scales: from data values to SVG coordinates, and the ranges they cover. */
interface Frame {
  sx: Scale;
  sy: Scale;
  x0: number;
  x1: number;
  y0: number;
  y1: number;
  logX: boolean;
  logY: boolean;
}

function frameOf(series: readonly ChartSeries[], options: ChartOptions): Frame {
  const logX = Boolean(options.logX);
  const logY = Boolean(options.logY);
  const xs = series.flatMap((one) => one.x);
  const ys = series.flatMap((one) => [...one.low, ...one.high, ...one.mean].filter((v): v is number => v !== null));
  const [x0, x1] = extent(xs, logX);
  const [ya, yb] = extent(ys, logY);
  const [y0, y1] = logY ? [ya / 1.08, yb * 1.08] : [ya - (yb - ya) * 0.04, yb + (yb - ya) * 0.04];
  // points (sensitivity) keep off the frame: half a category, or a few percent of the range
  const [xa, xb] = options.categories
    ? [x0 - 0.5, x1 + 0.5]
    : options.style === "bars"
      ? logX
        ? [x0 / 1.15, x1 * 1.15]
        : [x0 - (x1 - x0) * 0.04, x1 + (x1 - x0) * 0.04]
      : [x0, x1];
  const sx = scale(xa, xb, M.left, W - M.right, logX);
  const sy = scale(y0, y1, H - M.bottom, M.top, logY);
  return { sx, sy, x0, x1, y0, y1, logX, logY };
}

/** The frame, the grid and ticks of both axes, and their labels. */
function axes(series: readonly ChartSeries[], options: ChartOptions, f: Frame) {
  const distinct = [...new Set(series.flatMap((one) => one.x))].sort((a, b) => a - b);
  const xTicks = options.categories
    ? options.categories.map((_, i) => i)
    : options.style === "bars" && distinct.length <= 8
      ? distinct // the swept values themselves
      : ticks(f.x0, f.x1, f.logX);
  const middle = (M.top + H - M.bottom) / 2;
  return svg`<g class="axes">
    <rect x=${M.left} y=${M.top} width=${W - M.left - M.right} height=${H - M.top - M.bottom} class="frame"></rect>
    ${ticks(f.y0, f.y1, f.logY).map(
      (v) => svg`<line x1=${M.left} x2=${W - M.right} y1=${f.sy(v)} y2=${f.sy(v)} class="grid"></line>
        <text x=${M.left - 6} y=${f.sy(v) + 4} text-anchor="end">${tickLabel(v)}</text>`,
    )}
    ${xTicks.map(
      (v) => svg`<line x1=${f.sx(v)} x2=${f.sx(v)} y1=${H - M.bottom} y2=${H - M.bottom + 4} class="tick"></line>
        <text x=${f.sx(v)} y=${H - M.bottom + 16} text-anchor="middle">${options.categories ? (options.categories[v] ?? "") : tickLabel(v)}</text>`,
    )}
    <text x=${(M.left + W - M.right) / 2} y=${H - 6} text-anchor="middle" class="label">${options.xLabel}</text>
    <text x="12" y=${middle} transform="rotate(-90 12 ${middle})" text-anchor="middle" class="label">${options.yLabel}</text>
  </g>`;
}

/** One series: its band (learning curves) or its error bars and points (sensitivity), and its line. */
function seriesShape(one: ChartSeries, i: number, options: ChartOptions, f: Frame, clip: string) {
  const color = PALETTE[i % PALETTE.length] as string;
  const { sx, sy, logY } = f;
  const at = (k: number, values: (number | null)[]): [number, number] => [
    sx(one.x[k] as number),
    sy(values[k] as number),
  ];
  const idx = one.x.map((_, k) => k).filter((k) => one.mean[k] !== null && (!logY || (one.mean[k] as number) > 0));
  const positive = (v: number | null | undefined) => v !== null && v !== undefined && (!logY || v > 0);
  let marks: unknown = nothing;
  if (options.style === "band") {
    const banded = idx.filter((k) => one.high[k] !== null && positive(one.low[k]));
    const outline = [...banded.map((k) => at(k, one.high)), ...banded.map((k) => at(k, one.low)).reverse()];
    marks = banded.length > 1 ? svg`<path d="${pathOf(outline)}Z" fill=${color} class="band"></path>` : nothing;
  } else {
    marks = svg`${idx
      .filter((k) => one.high[k] !== null && positive(one.low[k]))
      .map(
        (k) =>
          svg`<line x1=${sx(one.x[k] as number)} x2=${sx(one.x[k] as number)} y1=${sy(one.low[k] as number)} y2=${sy(one.high[k] as number)} stroke=${color} class="errorbar"></line>`,
      )}${idx.map((k) => svg`<circle cx=${at(k, one.mean)[0]} cy=${at(k, one.mean)[1]} r="3.5" fill=${color} class="point"></circle>`)}`;
  }
  const line = idx.map((k) => at(k, one.mean));
  return svg`<g class="series" data-label=${one.label} clip-path="url(#${clip})">
    ${marks}
    ${line.length > 0 ? svg`<path d=${pathOf(line)} stroke=${color} class=${one.best ? "line best" : "line"}></path>` : nothing}
  </g>`;
}

export function bandChart(series: readonly ChartSeries[], options: ChartOptions) {
  const f = frameOf(series, options);
  const clip = `clip-${(chartCount += 1)}`;
  return html`<figure class="study-figure">
    <figcaption>${options.title}</figcaption>
    <svg
      viewBox="0 0 ${W} ${H}"
      class="study-chart"
      role="img"
      aria-label="${options.title}: ${options.yLabel} against ${options.xLabel}"
    >
      <defs>
        <clipPath id=${clip}>
          <rect x=${M.left} y=${M.top} width=${W - M.left - M.right} height=${H - M.top - M.bottom}></rect>
        </clipPath>
      </defs>
      ${axes(series, options, f)} ${series.map((one, i) => seriesShape(one, i, options, f, clip))}
    </svg>
    <ul class="chart-legend">
      ${series.map(
        (one, i) =>
          html`<li>
            <span class="swatch" style=${styleMap({ background: PALETTE[i % PALETTE.length] })}></span>${
              one.label + (one.best ? " (best)" : "")
            }
          </li>`,
      )}
    </ul>
  </figure>`;
}
