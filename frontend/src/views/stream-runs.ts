/**
 * Stream runs (a world of kind `stream`, fed by a client: GET /api/streams): listed in the sidebar under
 * the runs, and, once one is selected, its strip chart in the Live tab, the nexting paper's figure: the
 * chosen sensors over the last records, and each chosen demon's prediction made at the time beside the
 * discounted return that followed, computed afterwards from the stream
 * (GET /api/streams/{id}/history). Selecting a stream run leaves the grid run selection (a stream run has
 * no episodes, steps or commands) and shows its phase plane in the embedded live view (POST /api/view).
 */
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import { attempt, selectRun } from "../app/actions";
import { queryClient, watchQuery } from "../app/queries";
import type { AppStore } from "../app/state";
import { ApiError, api, unwrap } from "../api/client";
import type { Demon, StreamHistory, StreamRun } from "../api/types";
import { formatCount, formatNumber } from "../lib/format";
import { type Columns, demonColumns, pickNames, sensorColumns, stripError } from "../lib/stream-history";
import { h, replaceChildren, section, setText } from "../ui/dom";
import { lineLook, plotSize } from "./plots";

const LIST_MS = 2000;
const HISTORY_MS = 1000;
const RECORDS = 1000; // the strip's window
const SHOWN = 4; // sensors and demons ticked at first
const MAX_SHOWN = 8;
const MAX_BOXES = 40; // demons offered as boxes (a Horde of thousands: the first ones)
const DEMONS_MS = 1000;
const TABLE_ROWS = 40; // rows of the stream's demon table (a Horde of thousands: the first ones)
const PREDICTION = "#0072B2";
const RETURN = "#111827";
const SENSOR = "#009E73";

export interface StreamViews {
  /** the sidebar's list of stream runs */
  list: HTMLElement;
  /** the Live tab's strip chart of the selected stream run (hidden while none is) */
  strip: HTMLElement;
}

interface Plot {
  figure: HTMLElement;
  caption: HTMLElement;
  box: HTMLElement;
  plot: uPlot | null;
  kind: "sensor" | "demon";
}

export function streamRuns(store: AppStore): StreamViews {
  let runs: StreamRun[] = [];
  let selected: string | null = null;
  let sensors: string[] = [];
  let demons: string[] = [];

  // ---------------------------------------------------------------- the list
  const items = h("ul", { class: "run-list", "aria-label": "Stream runs" });
  const empty = h(
    "p",
    { class: "muted" },
    "No stream runs. A client starts one with POST /api/streams and pushes records to it (see the README).",
  );
  const list = section(
    { class: "panel stream-runs", id: "stream-runs-title", title: "Stream runs" },
    h(
      "p",
      { class: "hint" },
      "Runs that learn from records a robot or a replayed log pushes. Select one to see its phase plane and its strip chart.",
    ),
    items,
    empty,
  );
  const renderList = () => {
    empty.hidden = runs.length > 0;
    replaceChildren(
      items,
      runs.map((run) =>
        h(
          "li",
          { class: run.id === selected ? "run-item selected" : "run-item", dataset: { stream: run.id } },
          h(
            "button",
            {
              type: "button",
              class: "link",
              "aria-pressed": run.id === selected ? "true" : "false",
              onclick: () => void attempt(store, () => choose(run.id)),
            },
            `${run.name || "stream"} · ${run.id.slice(0, 6)}`,
          ),
          h(
            "span",
            { class: "hint" },
            ` ${formatCount(run.learned)} records learned of ${formatCount(run.received)} received · ${run.sensors.length} sensors · ${run.demons.length} demons`,
          ),
        ),
      ),
    );
  };

  const choose = async (id: string) => {
    if (store.state.selectedRunId !== null) await selectRun(store, null);
    selected = id;
    const run = runs.find((r) => r.id === id);
    sensors = pickNames(run?.sensors ?? [], sensors, SHOWN, MAX_SHOWN);
    demons = pickNames(run?.demons ?? [], demons, SHOWN, MAX_SHOWN);
    store.update({ tab: "live" });
    renderList();
    renderStrip();
    history.update(historyWatch());
    void history.refetch();
    demonRows.update(demonsWatch());
    void demonRows.refetch();
    if (store.state.liveView.state === "on") {
      try {
        await unwrap(api.POST("/api/view", { body: { run: id } }));
      } catch (error) {
        if (!(error instanceof ApiError && (error.status === 404 || error.status === 409))) throw error;
      }
    }
  };

  watchQuery(
    queryClient,
    { queryKey: ["streams"], queryFn: () => unwrap(api.GET("/api/streams")), every: LIST_MS },
    (read) => {
      runs = read;
      if (selected !== null && !runs.some((r) => r.id === selected)) {
        selected = null;
        renderStrip();
      }
      renderList();
      renderCounts();
    },
  );
  // Selecting a grid run leaves the stream run.
  store.subscribe(
    (state) => {
      if (state.selectedRunId !== null && selected !== null) {
        selected = null;
        renderList();
        renderStrip();
        history.update(historyWatch());
      }
    },
    ["selectedRunId"],
  );

  // ---------------------------------------------------------------- the strip chart
  const title = h("h2", { id: "stream-strip-title" }, "Stream run");
  const counts = h("p", { class: "hint", "aria-live": "polite" });
  const sensorBoxes = h("fieldset", { class: "stream-pick" }, h("legend", {}, "Sensors"));
  const demonBoxes = h("fieldset", { class: "stream-pick" }, h("legend", {}, "Demons"));
  const grid = h("div", { class: "chart-grid" });
  const tableBody = h("tbody");
  const demonTable = h(
    "table",
    { class: "stream-demons", dataset: { testid: "stream-demons" } },
    h(
      "caption",
      {},
      "Demons at the last record: prediction, RUPEE (how far it still is from its fixed point) and UDE (how surprised it is).",
    ),
    h(
      "thead",
      {},
      h("tr", {}, h("th", {}, "demon"), h("th", {}, "prediction"), h("th", {}, "RUPEE"), h("th", {}, "UDE")),
    ),
    tableBody,
  );
  const snapshotLink = h(
    "a",
    { class: "hint", download: "stream-snapshot.json", dataset: { testid: "stream-snapshot" } },
    "Download a snapshot (POST it to /api/streams/import to go on from here)",
  );
  const renderDemons = (rows: Demon[]) =>
    replaceChildren(
      tableBody,
      rows
        .slice(0, TABLE_ROWS)
        .map((d) =>
          h(
            "tr",
            { dataset: { demon: d.name } },
            h("td", {}, d.metrics.diverged ? `${d.name} (diverged)` : d.name),
            h("td", {}, formatNumber(d.prediction)),
            h("td", {}, formatNumber(d.metrics.rupee)),
            h("td", {}, formatNumber(d.metrics.ude)),
          ),
        ),
    );
  const strip = h(
    "section",
    { class: "panel stream-strip", "aria-labelledby": "stream-strip-title", dataset: { testid: "stream-strip" } },
    title,
    counts,
    h(
      "p",
      { class: "hint" },
      `The last ${formatCount(RECORDS)} records, by their number in the stream. Green: a sensor's reading. `,
      "Blue: the demon's prediction, made on observing the record. Dashed black: the discounted return that actually followed, ",
      "computed afterwards from the later records (blank for the newest records, whose return is not known yet, and before a refused record; ",
      "it is the behaviour's return, so it is the answer only for on-policy demons). ",
      "No Evaluate here: a stream's records come from outside, so there is no copy of its world to roll a target policy out in; the realised return is the truth a stream has.",
    ),
    sensorBoxes,
    demonBoxes,
    grid,
    demonTable,
    snapshotLink,
  );
  strip.hidden = true;
  const plots = new Map<string, Plot>();

  const boxes = (offered: readonly string[], ticked: () => string[], set: (names: string[]) => void) =>
    offered.slice(0, MAX_BOXES).map((name) => {
      const tick = h("input", { type: "checkbox", checked: ticked().includes(name) });
      tick.addEventListener("change", () => {
        const now = ticked().filter((n) => n !== name);
        set(tick.checked ? [...now, name].slice(0, MAX_SHOWN) : now);
        renderStrip();
        history.update(historyWatch());
        void history.refetch();
      });
      return h("label", { class: "stream-tick" }, tick, ` ${name}`);
    });

  const renderCounts = () => {
    const run = runs.find((r) => r.id === selected);
    if (run) {
      setText(
        counts,
        `${formatCount(run.learned)} records learned of ${formatCount(run.received)} received; ${run.demons.length} demons over ${run.sensors.join(", ")}. Its phase plane is in the live view below.`,
      );
    }
  };

  const renderStrip = () => {
    const run = runs.find((r) => r.id === selected);
    strip.hidden = run === undefined;
    if (!run) {
      for (const plot of plots.values()) plot.plot?.destroy();
      plots.clear();
      replaceChildren(grid);
      return;
    }
    setText(title, `Stream run ${run.name || run.id.slice(0, 6)}: predictions beside realised returns`);
    snapshotLink.setAttribute("href", `/api/streams/${encodeURIComponent(run.id)}/snapshot`);
    renderCounts();
    replaceChildren(
      sensorBoxes,
      h("legend", {}, "Sensors"),
      ...boxes(
        run.sensors,
        () => sensors,
        (n) => (sensors = n),
      ),
    );
    replaceChildren(
      demonBoxes,
      h(
        "legend",
        {},
        `Demons${run.demons.length > MAX_BOXES ? ` (the first ${MAX_BOXES} of ${run.demons.length})` : ""}`,
      ),
      ...boxes(
        run.demons,
        () => demons,
        (n) => (demons = n),
      ),
    );
    const wanted = [...sensors.map((s) => `sensor:${s}`), ...demons.map((d) => `demon:${d}`)];
    for (const [key, plot] of plots) {
      if (!wanted.includes(key)) {
        plot.plot?.destroy();
        plots.delete(key);
      }
    }
    replaceChildren(
      grid,
      wanted.map((key) => {
        let plot = plots.get(key);
        if (!plot) {
          const kind = key.startsWith("sensor:") ? "sensor" : "demon";
          const name = key.slice(kind.length + 1);
          const caption = h("figcaption", {}, name);
          const box = h("div", { class: "chart-box" });
          const figure = h("figure", { class: "chart", dataset: { [kind]: name } }, caption, box);
          caption.style.borderLeftColor = kind === "sensor" ? SENSOR : PREDICTION;
          plot = { figure, caption, box, plot: null, kind };
          plots.set(key, plot);
        }
        return plot.figure;
      }),
    );
  };

  const historyWatch = () => ({
    queryKey: ["stream-history", selected ?? "", sensors.join(","), demons.join(",")],
    queryFn: (): Promise<StreamHistory> =>
      unwrap(
        api.GET("/api/streams/{stream_id}/history", {
          params: {
            path: { stream_id: selected ?? "" },
            query: { sensors: sensors.join(","), demons: demons.join(","), last: RECORDS },
          },
        }),
      ),
    every: HISTORY_MS,
    enabled: selected !== null && sensors.length > 0 && demons.length > 0 && store.state.tab === "live",
  });
  const history = watchQuery(queryClient, historyWatch(), (read) => {
    for (const [key, plot] of plots) {
      const name = key.slice(plot.kind.length + 1);
      if (plot.kind === "sensor") {
        draw(plot, sensorColumns(read, name), [{ label: name, stroke: SENSOR, width: 2 }]);
        continue;
      }
      const error = stripError(read, name);
      setText(
        plot.caption,
        read.returns[name] === null
          ? `${name} · its question reads other demons' predictions: no realised return`
          : error.count > 0
            ? `${name} · mean |prediction − return| ${formatNumber(error.meanAbsolute)} over ${formatCount(error.count)} records`
            : `${name} · no realised return known yet`,
      );
      draw(plot, demonColumns(read, name), [
        { label: "prediction", stroke: PREDICTION, width: 2 },
        { label: "realised return", stroke: RETURN, width: 1.5, dash: [6, 4] },
      ]);
    }
  });
  const demonsWatch = () => ({
    queryKey: ["stream-demons", selected ?? ""],
    queryFn: (): Promise<Demon[]> =>
      unwrap(api.GET("/api/streams/{stream_id}/demons", { params: { path: { stream_id: selected ?? "" } } })),
    every: DEMONS_MS,
    enabled: selected !== null && store.state.tab === "live",
  });
  const demonRows = watchQuery(queryClient, demonsWatch(), renderDemons);
  store.subscribe(() => {
    history.update(historyWatch());
    demonRows.update(demonsWatch());
  }, ["tab"]);

  new ResizeObserver(() => {
    for (const plot of plots.values()) plot.plot?.setSize(stripSize(plot.box));
  }).observe(grid);
  return { list, strip };
}

/** A strip plot: as wide as its cell, 0.6 of that high, at least 10 rem. */
const stripSize = (box: HTMLElement) => plotSize(box, 10, 0.6);

function draw(plot: Plot, columns: Columns, series: uPlot.Series[]): void {
  const data = columns as unknown as uPlot.AlignedData;
  if (columns[0].length < 2) return; // uPlot keeps a broken x range when it starts with fewer than two points
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
