/**
 * The live demon table of the selected run: per demon its prediction now (at the agent's state), the
 * Monte-Carlo truth once evaluated (from the world's start, beside the prediction there and the
 * error), the thesis's number when the scenario has one, RUPEE, UDE, and a `diverged` mark; a chart
 * toggle under each name, and an Evaluate and a Remove button per demon (removing takes two presses).
 * Cells are updated in place from the stream.
 */
import { attempt, evaluateDemon, notify, removeDemon, toggleCharted } from "../app/actions";
import type { AppState, AppStore } from "../app/state";
import type { Demon } from "../api/types";
import { exprText } from "../lib/expr";
import { formatEstimate, formatNumber, formatRelativeError } from "../lib/format";
import { readNumber } from "../lib/parse";
import { startPoint } from "../lib/world";
import { h, setText } from "../ui/dom";
import { field, numberInput } from "../ui/form";

const DEFAULT_ROLLOUTS = 100;
const REMOVE_CONFIRM_MS = 4000;

interface Row {
  tr: HTMLTableRowElement;
  now: HTMLElement;
  atStart: HTMLElement;
  truth: HTMLElement;
  error: HTMLElement;
  relative: HTMLElement;
  thesis: HTMLElement;
  rupee: HTMLElement;
  ude: HTMLElement;
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
  // One after the other: the server runs at most two evaluations at once (429 beyond).
  evaluateAll.addEventListener("click", async () => {
    evaluateAll.disabled = true;
    for (const demon of store.state.demons) if (!pending.has(demon.name)) await evaluate(demon.name);
    evaluateAll.disabled = false;
  });

  const makeRow = (demon: Demon): Row => {
    const cell = (cls = "num") => h("td", { class: cls });
    const row: Row = {
      tr: h("tr", { dataset: { demon: demon.name } }),
      now: cell(),
      atStart: cell(),
      truth: cell(),
      error: h("span", {}),
      relative: h("span", { class: "relative" }),
      thesis: cell(),
      rupee: cell(),
      ude: cell(),
      diverged: h("span", { class: "tag diverged", hidden: true }, "diverged"),
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
        h("span", { class: "demon-name" }, demon.name),
        demon.control ? h("span", { class: "tag" }, "control") : null,
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
    const { run, demons, live, evaluations, charted } = state;
    empty.hidden = run !== null;
    table.hidden = run === null;
    if (run === null) return;
    const [x, y] = startPoint(run.spec.world ?? {});
    setText(caption, `Demons of ${run.name ?? run.id.slice(0, 6)}: evaluated from the start (${x}, ${y})`);
    const thesis = run.spec.thesis?.predictions ?? {};
    // The server refuses (409) to change a finished or failed run.
    const status = live?.status ?? run.status;
    const closed = status === "finished" || status === "failed";
    const seen = new Set<string>();
    for (const demon of demons) {
      seen.add(demon.name);
      let row = rows.get(demon.name);
      if (!row) {
        row = makeRow(demon);
        rows.set(demon.name, row);
      }
      // Moved only when out of place: a row taken out of the page, even for a moment, loses the focus
      // and the click under way on its buttons (render runs 30 times a second).
      const at = body.children[seen.size - 1];
      if (at !== row.tr) body.insertBefore(row.tr, at ?? null);
      const metrics = live?.metrics[demon.name] ?? demon.metrics;
      const prediction = live ? live.predictions[demon.name] : demon.prediction;
      const evaluation = evaluations[demon.name];
      setText(row.now, formatNumber(prediction));
      setText(row.atStart, formatNumber(evaluation?.prediction));
      setText(row.truth, formatEstimate(evaluation?.truth, evaluation?.stderr));
      setText(row.error, formatNumber(evaluation?.error));
      setText(row.relative, evaluation ? formatRelativeError(evaluation.prediction, evaluation.truth) : "");
      setText(row.thesis, formatNumber(thesis[demon.name]));
      setText(row.rupee, formatNumber(metrics?.rupee));
      setText(row.ude, formatNumber(metrics?.ude));
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
        h("th", { scope: "col", rowspan: 2 }, "Demon"),
        h("th", { scope: "col", rowspan: 2, class: "num" }, "Prediction now"),
        h("th", { scope: "colgroup", colspan: 3, class: "group" }, "At the start: Monte-Carlo evaluation"),
        h("th", { scope: "col", rowspan: 2, class: "num" }, "Thesis"),
        h("th", { scope: "col", rowspan: 2, class: "num" }, "RUPEE"),
        h("th", { scope: "col", rowspan: 2, class: "num" }, "UDE"),
        h("th", { scope: "col", rowspan: 2 }, h("span", { class: "visually-hidden" }, "Actions")),
      ),
      h(
        "tr",
        {},
        h("th", { scope: "col", class: "num" }, "prediction"),
        h("th", { scope: "col", class: "num" }, "truth ± se"),
        h("th", { scope: "col", class: "num" }, "error"),
      ),
    ),
    body,
  );

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
        field("Rollouts per evaluation", rollouts, { class: "inline-field" }),
        evaluateAll,
      ),
    ),
    empty,
    h("div", { class: "table-scroll" }, table),
  );
}
