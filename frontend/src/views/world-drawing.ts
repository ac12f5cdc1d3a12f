/**
 * The live drawing of a world (SVG, y up): the grid of its steps, its regions coloured by kind with
 * their names, and the start point or rectangle. Redrawn from the form's current values on every edit.
 */
import type { WorldSpec } from "../api/types";
import { gridLines, regionFills } from "../lib/world";
import { h, replaceChildren, s } from "../ui/dom";

const isCssColor = (name: string): boolean => typeof CSS !== "undefined" && CSS.supports("color", name);

const finite = (...values: (number | undefined)[]): boolean =>
  values.every((v) => v !== undefined && Number.isFinite(v));

export function worldDrawing(): { element: HTMLElement; draw: (world: WorldSpec) => void } {
  const svg = s("svg", { class: "world-svg", role: "img", "aria-labelledby": "world-drawing-title" });
  const title = s("title", { id: "world-drawing-title" });
  const legend = h(
    "ul",
    { class: "legend", "aria-label": "Colours of the drawing" },
    h("li", {}, h("span", { class: "swatch obstacle" }), "obstacle"),
    h("li", {}, h("span", { class: "swatch positive" }), "terminal, reward > 0"),
    h("li", {}, h("span", { class: "swatch negative" }), "terminal, reward < 0"),
    h("li", {}, h("span", { class: "swatch zone" }), "zone"),
    h("li", {}, h("span", { class: "swatch start" }), "start"),
  );
  const note = h("p", { class: "hint", hidden: true });

  const draw = (world: WorldSpec) => {
    const { width, height } = world;
    const drawable = finite(width, height) && width > 0 && height > 0;
    note.hidden = drawable;
    svg.style.display = drawable ? "" : "none";
    if (!drawable) {
      note.textContent = "Enter a positive width and height to see the world.";
      return;
    }
    const size = Math.min(width, height);
    const line = size / 250;
    const flipY = (y: number) => height - y; // SVG's y points down, the world's up
    const regions = (world.regions ?? []).filter((r) => r.rect.length === 4 && finite(...r.rect));
    title.textContent = `The world: ${width} by ${height}, ${regions.length} regions`;
    svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
    svg.setAttribute("preserveAspectRatio", "xMidYMid meet");

    const grid = s(
      "g",
      { class: "grid", stroke: "#9ca3af", "stroke-width": line },
      gridLines(width, world.step).map((x) => s("line", { x1: x, y1: 0, x2: x, y2: height })),
      gridLines(height, world.step).map((y) => s("line", { x1: 0, y1: flipY(y), x2: width, y2: flipY(y) })),
    );
    const shapes = regions.map((region) => {
      const [x0, y0, x1, y1] = region.rect as [number, number, number, number];
      const fills = regionFills(region, isCssColor);
      const band = (x1 - x0) / fills.length;
      return s(
        "g",
        { class: `region region-${region.kind}`, "data-region": region.name },
        fills.map((f, i) =>
          s("rect", {
            x: x0 + i * band,
            y: flipY(y1),
            width: band,
            height: y1 - y0,
            fill: f.color,
            "fill-opacity": f.opacity,
          }),
        ),
        s("rect", {
          x: x0,
          y: flipY(y1),
          width: x1 - x0,
          height: y1 - y0,
          fill: "none",
          stroke: "#111827",
          "stroke-width": line * 1.5,
        }),
        s(
          "text",
          {
            x: (x0 + x1) / 2,
            y: flipY((y0 + y1) / 2),
            "font-size": Math.min(size / 22, (x1 - x0) / 4),
            "text-anchor": "middle",
            "dominant-baseline": "central",
            class: "region-label",
            // White on the dark fills (obstacles, terminals), ink on the light ones.
            fill: region.kind === "obstacle" || region.kind === "terminal" ? "#ffffff" : "#0b0f19",
          },
          region.name,
        ),
      );
    });
    replaceChildren(
      svg,
      title,
      s("rect", { x: 0, y: 0, width, height, fill: "#ffffff", stroke: "#111827", "stroke-width": line * 3 }),
      grid,
      shapes,
      startMark(world.start ?? [0, 0], flipY, size),
    );
  };

  return { element: h("div", { class: "world-drawing" }, svg, note, legend), draw };
}

function startMark(start: number[], flipY: (y: number) => number, size: number): SVGElement | null {
  if (start.length === 4 && finite(...start)) {
    const [x0, y0, x1, y1] = start as [number, number, number, number];
    return s("rect", {
      class: "start",
      x: x0,
      y: flipY(y1),
      width: x1 - x0,
      height: y1 - y0,
      fill: "#2563eb",
      "fill-opacity": 0.15,
      stroke: "#1d4ed8",
      "stroke-width": size / 120,
      "stroke-dasharray": `${size / 40} ${size / 60}`,
    });
  }
  const [x, y] = start;
  if (!finite(x, y)) return null;
  return s("circle", {
    class: "start",
    cx: x,
    cy: flipY(y as number),
    r: size / 24,
    fill: "#1d4ed8",
    stroke: "#ffffff",
    "stroke-width": size / 150,
  });
}
