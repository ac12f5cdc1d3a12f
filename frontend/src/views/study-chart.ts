/**
 * A small SVG chart of means with 95 % bands: learning curves (a line and a shaded band per series) and
 * sensitivity curves (points with error bars joined by lines). Log scales where asked, a legend of
 * the series below, and a title that says what is drawn. Pure drawing: no state, no requests.
 */
import { h, s } from "../ui/dom";

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

export function bandChart(series: readonly ChartSeries[], options: ChartOptions): HTMLElement {
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
  const svg = s("svg", {
    viewBox: `0 0 ${W} ${H}`,
    class: "study-chart",
    role: "img",
    "aria-label": `${options.title}: ${options.yLabel} against ${options.xLabel}`,
  });
  const axes = s("g", { class: "axes" });
  axes.append(
    s("rect", { x: M.left, y: M.top, width: W - M.left - M.right, height: H - M.top - M.bottom, class: "frame" }),
  );
  for (const v of ticks(y0, y1, logY)) {
    const y = sy(v);
    axes.append(s("line", { x1: M.left, x2: W - M.right, y1: y, y2: y, class: "grid" }));
    axes.append(s("text", { x: M.left - 6, y: y + 4, "text-anchor": "end" }, tickLabel(v)));
  }
  const distinct = [...new Set(xs)].sort((a, b) => a - b);
  const xTicks = options.categories
    ? options.categories.map((_, i) => i)
    : options.style === "bars" && distinct.length <= 8
      ? distinct // the swept values themselves
      : ticks(x0, x1, logX);
  for (const v of xTicks) {
    const x = sx(v);
    axes.append(s("line", { x1: x, x2: x, y1: H - M.bottom, y2: H - M.bottom + 4, class: "tick" }));
    const text = options.categories ? (options.categories[v] ?? "") : tickLabel(v);
    axes.append(s("text", { x, y: H - M.bottom + 16, "text-anchor": "middle" }, text));
  }
  axes.append(
    s("text", { x: (M.left + W - M.right) / 2, y: H - 6, "text-anchor": "middle", class: "label" }, options.xLabel),
  );
  axes.append(
    s(
      "text",
      {
        x: 12,
        y: (M.top + H - M.bottom) / 2,
        transform: `rotate(-90 12 ${(M.top + H - M.bottom) / 2})`,
        "text-anchor": "middle",
        class: "label",
      },
      options.yLabel,
    ),
  );
  const clip = `clip-${(chartCount += 1)}`;
  svg.append(
    s(
      "defs",
      {},
      s(
        "clipPath",
        { id: clip },
        s("rect", { x: M.left, y: M.top, width: W - M.left - M.right, height: H - M.top - M.bottom }),
      ),
    ),
  );
  svg.append(axes);

  series.forEach((one, i) => {
    const color = PALETTE[i % PALETTE.length] as string;
    const group = s("g", { class: "series", "data-label": one.label, "clip-path": `url(#${clip})` });
    const idx = one.x.map((_, k) => k).filter((k) => one.mean[k] !== null && (!logY || (one.mean[k] as number) > 0));
    if (options.style === "band") {
      const banded = idx.filter(
        (k) => one.low[k] !== null && one.high[k] !== null && (!logY || (one.low[k] as number) > 0),
      );
      if (banded.length > 1) {
        const upper = banded.map((k): [number, number] => [sx(one.x[k] as number), sy(one.high[k] as number)]);
        const lower = banded.map((k): [number, number] => [sx(one.x[k] as number), sy(one.low[k] as number)]).reverse();
        group.append(s("path", { d: `${pathOf([...upper, ...lower])}Z`, fill: color, class: "band" }));
      }
    } else {
      for (const k of idx) {
        const x = sx(one.x[k] as number);
        const low = one.low[k];
        const high = one.high[k];
        if (low === null || high === null || (logY && (low as number) <= 0)) continue;
        group.append(
          s("line", { x1: x, x2: x, y1: sy(low as number), y2: sy(high as number), stroke: color, class: "errorbar" }),
        );
      }
      for (const k of idx) {
        group.append(
          s("circle", {
            cx: sx(one.x[k] as number),
            cy: sy(one.mean[k] as number),
            r: 3.5,
            fill: color,
            class: "point",
          }),
        );
      }
    }
    const line = idx.map((k): [number, number] => [sx(one.x[k] as number), sy(one.mean[k] as number)]);
    if (line.length > 0)
      group.append(s("path", { d: pathOf(line), stroke: color, class: one.best ? "line best" : "line" }));
    svg.append(group);
  });

  const legend = h(
    "ul",
    { class: "chart-legend" },
    series.map((one, i) =>
      h(
        "li",
        {},
        h("span", { class: "swatch", style: `background:${PALETTE[i % PALETTE.length]}` }),
        one.label + (one.best ? " (best)" : ""),
      ),
    ),
  );
  return h("figure", { class: "study-figure" }, h("figcaption", {}, options.title), svg, legend);
}
