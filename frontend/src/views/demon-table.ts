/**
 * The live demon table of the selected run: per demon its prediction now (at the agent's state), the
 * truth once evaluated (from the world's start, beside the prediction there and the error), the
 * thesis's number when the scenario has one, RUPEE, UDE, the step size it takes now (α now: adaptive
 * demons tune theirs), and a `diverged` mark; a colour dot and a chart
 * toggle under each name, and an Evaluate and a Remove button per demon (removing takes two presses).
 * Above it a summary (how many demons learn, how many diverged, mean RUPEE) and a filter. At Horde scale
 * the table scrolls in its own box and only the rows in sight exist (@tanstack/virtual-core). Cells are
 * updated in place from the stream.
 */
import { Virtualizer, elementScroll, observeElementOffset, observeElementRect } from "@tanstack/virtual-core";
import { attempt, evaluateDemon, notify, removeDemon, toggleCharted } from "../app/actions";
import type { AppState, AppStore } from "../app/state";
import type { Demon } from "../api/types";
import { type DemonFilter, demonSummary, filterDemons } from "../lib/demons";
import { exprText } from "../lib/expr";
import { formatNumber, formatRelativeError, formatTruth, truthOf } from "../lib/format";
import { type Term, tip } from "../lib/glossary";
import { readNumber } from "../lib/parse";
import { startPoint } from "../lib/world";
import { h, options, setText } from "../ui/dom";
import { field, numberInput } from "../ui/form";

const DEFAULT_ROLLOUTS = 100;
const REMOVE_CONFIRM_MS = 4000;
/** Above this many shown demons the table scrolls in its own box and keeps only the rows in sight. */
export const VIRTUAL_FROM = 60;
const ROW_ESTIMATE_PX = 72;
const COLUMNS = 10;

function explained(tag: "th", term: Term, props: Record<string, unknown>, label: string): HTMLElement {
  return h(tag, { ...props, title: tip(term) }, h("span", { class: "term" }, label));
}

interface Row {
  tr: HTMLTableRowElement;
  dot: HTMLElement;
  now: HTMLElement;
  atStart: HTMLElement;
  truth: HTMLElement;
  error: HTMLElement;
  relative: HTMLElement;
  thesis: HTMLElement;
  rupee: HTMLElement;
  ude: HTMLElement;
  stepSize: HTMLElement;
  diverged: HTMLElement;
  chart: HTMLInputElement;
  evaluate: HTMLButtonElement;
  remove: HTMLButtonElement;
  /** until when a second press of Remove removes the demon (ms since the epoch) */
  confirmUntil: number;
}

export function demonTable(store: AppStore): HTMLElement {
  const rollouts = numberInput(DEFAULT_ROLLOUTS, { name: "rollouts" });
  const evaluateAll = h("button", { type: "button" }, "Evaluate all");
  const caption = h("caption", {});
  const body = h("tbody", {});
  const empty = h("p", { class: "muted" }, "Select a run to see its demons.");
  const summary = h("p", { class: "demon-summary", "aria-live": "off", dataset: { testid: "demon-summary" } });
  const search = h("input", {
    type: "search",
    id: "demon-search",
    autocomplete: "off",
    placeholder: "name or question",
  });
  const show = h(
    "select",
    { id: "demon-show" },
    options([
      ["all", "all demons"],
      ["learning", "learning"],
      ["diverged", "diverged"],
      ["charted", "charted"],
      ["control", "control demons"],
    ]),
  );
  const topSpacer = h("tr", { class: "spacer", "aria-hidden": "true" }, h("td", { colspan: COLUMNS }));
  const bottomSpacer = h("tr", { class: "spacer", "aria-hidden": "true" }, h("td", { colspan: COLUMNS }));
  const scrollBox = h("div", { class: "table-scroll" });
  const rows = new Map<string, Row>();
  const pending = new Set<string>();
  const removing = new Set<string>();

  const evaluate = async (demon: string) => {
    const episodes = readNumber(rollouts.value);
    pending.add(demon);
    render(store.state);
    await attempt(store, async () => {
      await evaluateDemon(store, demon, episodes);
      notify(store, `Evaluated '${demon}' over ${episodes} rollouts.`);
    });
    pending.delete(demon);
    render(store.state);
  };
  // One after the other: the server runs at most two evaluations at once (429 beyond). "All" means the
  // demons the filter shows.
  evaluateAll.addEventListener("click", async () => {
    evaluateAll.disabled = true;
    for (const demon of shownDemons(store.state)) if (!pending.has(demon.name)) await evaluate(demon.name);
    evaluateAll.disabled = false;
  });

  const filterNow = (): DemonFilter => ({ text: search.value, show: show.value as DemonFilter["show"] });
  const shownDemons = (state: Readonly<AppState>): Demon[] =>
    filterDemons(state.demons, filterNow(), state.live?.metrics ?? {}, state.charted);
  search.addEventListener("input", () => render(store.state));
  show.addEventListener("change", () => render(store.state));

  // Only the rows in sight (plus a few) exist once the table is long.
  const virtualizer = new Virtualizer<HTMLDivElement, HTMLTableRowElement>({
    count: 0,
    getScrollElement: () => scrollBox,
    estimateSize: () => ROW_ESTIMATE_PX,
    overscan: 8,
    observeElementRect,
    observeElementOffset,
    scrollToFn: elementScroll,
    getItemKey: (index) => currentNames[index] ?? index,
    onChange: () => {
      if (!rendering) render(store.state);
    },
  });
  let rendering = false;
  let currentNames: string[] = [];
  let mounted = false;

  const makeRow = (demon: Demon): Row => {
    const cell = (cls = "num") => h("td", { class: cls });
    const row: Row = {
      tr: h("tr", { dataset: { demon: demon.name } }),
      dot: h("span", { class: "swatch-dot", "aria-hidden": "true" }),
      now: cell(),
      atStart: cell(),
      truth: cell(),
      error: h("span", {}),
      relative: h("span", { class: "relative" }),
      thesis: cell(),
      rupee: cell(),
      ude: cell(),
      stepSize: cell(),
      diverged: h("span", { class: "tag diverged", hidden: true, title: tip("diverged") }, "diverged"),
      chart: h("input", { type: "checkbox", "aria-label": `Chart ${demon.name}` }), // beside the name: saves a column
      evaluate: h("button", { type: "button", class: "small", "aria-label": `Evaluate ${demon.name}` }, "Evaluate"),
      remove: h("button", { type: "button", class: "small danger" }),
      confirmUntil: 0,
    };
    row.chart.addEventListener("change", () => toggleCharted(store, demon.name, row.chart.checked));
    row.evaluate.addEventListener("click", () => void evaluate(demon.name));
    row.remove.addEventListener("click", () => onRemove(demon.name, row));
    const question = `${demon.spec.policy?.kind === "of" ? `follows ${demon.spec.policy.demon}` : (demon.spec.policy?.kind ?? "uniform")} · cumulant ${exprText(demon.spec.cumulant)}`;
    row.tr.append(
      h(
        "th",
        { scope: "row" },
        row.dot,
        h("span", { class: "demon-name" }, demon.name),
        demon.control ? h("span", { class: "tag", title: tip("control") }, "control") : null,
        row.diverged,
        h("span", { class: "question" }, question),
        h("label", { class: "chart-toggle" }, row.chart, "chart"),
      ),
      row.now,
      row.atStart,
      row.truth,
      h("td", { class: "num" }, row.error, row.relative),
      row.thesis,
      row.rupee,
      row.ude,
      row.stepSize,
      h("td", {}, h("div", { class: "row-actions" }, row.evaluate, row.remove)),
    );
    return row;
  };

  // Removing takes two presses, so a stray click cannot throw a demon (and its learning) away.
  const onRemove = (demon: string, row: Row) => {
    const runId = store.state.selectedRunId;
    if (runId === null) return;
    if (Date.now() < row.confirmUntil) {
      row.confirmUntil = 0;
      removing.add(demon);
      render(store.state);
      void attempt(store, async () => {
        await removeDemon(store, runId, demon);
        notify(store, `Removed demon '${demon}' from the run.`);
      }).finally(() => {
        removing.delete(demon);
        render(store.state);
      });
      return;
    }
    row.confirmUntil = Date.now() + REMOVE_CONFIRM_MS;
    render(store.state);
    // A paused run sends no messages: the button turns back by itself.
    window.setTimeout(() => render(store.state), REMOVE_CONFIRM_MS + 50);
  };

  const render = (state: Readonly<AppState>) => {
    rendering = true;
    try {
      renderNow(state);
    } finally {
      rendering = false;
    }
  };

  const renderNow = (state: Readonly<AppState>) => {
    const { run, demons, live, evaluations, charted } = state;
    empty.hidden = run !== null;
    table.hidden = run === null;
    tools.hidden = run === null;
    if (run === null) return;
    const [x, y] = startPoint(run.spec.world ?? {});
    setText(caption, `Demons of ${run.name ?? run.id.slice(0, 6)}: evaluated from the start (${x}, ${y})`);
    const totals = demonSummary(demons, live?.metrics ?? {});
    setText(
      summary,
      `${totals.demons.toLocaleString("en-US")} demons · ${totals.learning.toLocaleString("en-US")} learning · ` +
        `${totals.diverged.toLocaleString("en-US")} diverged · mean RUPEE ${formatNumber(totals.meanRupee)}`,
    );
    const thesis = run.spec.thesis?.predictions ?? {};
    // The server refuses (409) to change a finished or failed run.
    const status = live?.status ?? run.status;
    const closed = status === "finished" || status === "failed";
    const shown = shownDemons(state);
    currentNames = shown.map((d) => d.name);
    const virtual = shown.length > VIRTUAL_FROM;
    scrollBox.classList.toggle("virtual", virtual);
    let visible: Demon[] = shown;
    let before = 0;
    let after = 0;
    if (virtual) {
      if (virtualizer.options.count !== shown.length) {
        virtualizer.setOptions({ ...virtualizer.options, count: shown.length });
      }
      if (!mounted) {
        mounted = true;
        virtualizer._didMount();
      }
      virtualizer._willUpdate();
      const items = virtualizer.getVirtualItems();
      visible = items.map((item) => shown[item.index]).filter((d): d is Demon => d !== undefined);
      before = items[0]?.start ?? 0;
      after = Math.max(0, virtualizer.getTotalSize() - (items.at(-1)?.end ?? 0));
    }
    (topSpacer.firstChild as HTMLElement).style.height = `${before}px`;
    (bottomSpacer.firstChild as HTMLElement).style.height = `${after}px`;
    topSpacer.hidden = before === 0;
    bottomSpacer.hidden = after === 0;
    if (body.firstChild !== topSpacer) body.prepend(topSpacer);
    const seen = new Set<string>();
    for (const demon of visible) {
      seen.add(demon.name);
      let row = rows.get(demon.name);
      if (!row) {
        row = makeRow(demon);
        rows.set(demon.name, row);
      }
      row.tr.dataset.index = String(currentNames.indexOf(demon.name));
      // Moved only when out of place: a row taken out of the page, even for a moment, loses the focus
      // and the click under way on its buttons (render runs 30 times a second).
      const at = body.children[seen.size];
      if (at !== row.tr) body.insertBefore(row.tr, at ?? null);
      if (virtual) virtualizer.measureElement(row.tr);
      row.dot.style.background = demon.colour;
      const metrics = live?.metrics[demon.name] ?? demon.metrics;
      const prediction = live ? live.predictions[demon.name] : demon.prediction;
      const evaluation = evaluations[demon.name];
      setText(row.now, formatNumber(prediction));
      setText(row.atStart, formatNumber(evaluation?.prediction));
      // Against the exact answer where the world has one (the Monte-Carlo mean is cut at the rollouts' cap).
      const truth = truthOf(evaluation);
      setText(row.truth, formatTruth(evaluation));
      setText(row.error, formatNumber(evaluation && truth !== null ? (evaluation.prediction ?? NaN) - truth : null));
      setText(row.relative, evaluation ? formatRelativeError(evaluation.prediction, truth) : "");
      setText(row.thesis, formatNumber(thesis[demon.name]));
      setText(row.rupee, formatNumber(metrics?.rupee));
      setText(row.ude, formatNumber(metrics?.ude));
      setText(row.stepSize, formatNumber(metrics?.step_size));
      // A diverged demon is frozen by the server; its numbers stop, the mark says why.
      row.diverged.hidden = !metrics?.diverged;
      row.chart.checked = charted.includes(demon.name);
      const busy = pending.has(demon.name);
      row.evaluate.disabled = busy;
      setText(row.evaluate, busy ? "Evaluating…" : "Evaluate");
      const confirming = Date.now() < row.confirmUntil;
      row.remove.disabled = closed || removing.has(demon.name);
      setText(row.remove, removing.has(demon.name) ? "Removing…" : confirming ? "Really remove?" : "Remove");
      row.remove.setAttribute("aria-label", confirming ? `Really remove ${demon.name}?` : `Remove ${demon.name}`);
    }
    for (const [name, row] of rows) {
      if (!seen.has(name)) {
        row.tr.remove();
        rows.delete(name);
      }
    }
    if (body.lastChild !== bottomSpacer) body.append(bottomSpacer);
  };

  const table = h(
    "table",
    { class: "demon-table", "aria-live": "off" },
    caption,
    h(
      "thead",
      {},
      h(
        "tr",
        {},
        explained("th", "demon", { scope: "col", rowspan: 2 }, "Demon"),
        explained("th", "prediction", { scope: "col", rowspan: 2, class: "num" }, "Prediction now"),
        explained("th", "truth", { scope: "colgroup", colspan: 3, class: "group" }, "At the start: evaluation"),
        explained("th", "thesis", { scope: "col", rowspan: 2, class: "num" }, "Thesis"),
        explained("th", "rupee", { scope: "col", rowspan: 2, class: "num" }, "RUPEE"),
        explained("th", "ude", { scope: "col", rowspan: 2, class: "num" }, "UDE"),
        explained("th", "stepSize", { scope: "col", rowspan: 2, class: "num" }, "α now"),
        h("th", { scope: "col", rowspan: 2 }, h("span", { class: "visually-hidden" }, "Actions")),
      ),
      h(
        "tr",
        {},
        explained("th", "prediction", { scope: "col", class: "num" }, "prediction"),
        explained("th", "truth", { scope: "col", class: "num" }, "truth (± se)"),
        h("th", { scope: "col", class: "num", title: "prediction − truth, and relative to the truth" }, "error"),
      ),
    ),
    body,
  );

  const tools = h(
    "div",
    { class: "row tight demon-tools" },
    summary,
    field("Find demons", search, { class: "inline-field" }),
    field("Show", show, { class: "inline-field" }),
  );
  scrollBox.append(table);

  store.subscribe(render, ["run", "demons", "live", "evaluations", "charted"]);
  render(store.state);

  return h(
    "section",
    { class: "panel demons-panel", "aria-labelledby": "demons-title" },
    h(
      "div",
      { class: "panel-head" },
      h("h2", { id: "demons-title" }, "Demons"),
      h(
        "div",
        { class: "row tight" },
        field("Rollouts per evaluation", rollouts, { class: "inline-field", term: "truth" }),
        evaluateAll,
      ),
    ),
    tools,
    empty,
    scrollBox,
  );
}
