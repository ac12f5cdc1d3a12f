/**
 * The live demon table of the selected run: per demon its prediction now (at the agent's state), the
 * truth once evaluated (beside the prediction there and the error: from the world's start on the grid world,
 * from the agent's state on a world evaluated by rollouts; a world with no evaluation says why), the
 * thesis's number when the scenario has one, RUPEE, UDE, the step size it takes now (α now: adaptive
 * demons tune theirs), and a `diverged` mark; a colour dot and a chart
 * toggle under each name, and an Evaluate and a Remove button per demon (removing takes two presses).
 * Above it a summary (how many demons learn, how many diverged, mean RUPEE) and a filter. At Horde scale
 * the table scrolls in its own box and only the rows in sight exist (@tanstack/virtual-core). The rows
 * are lit-html templates kept by the demon's name (`repeat`): cells are updated in place from the stream.
 */
import { Virtualizer, elementScroll, observeElementOffset, observeElementRect } from "@tanstack/virtual-core";
import { attempt, evaluateDemon, notify, removeDemon, toggleCharted } from "../app/actions";
import { type App, type AppState, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import type { Demon } from "../api/types";
import { evaluationKind, gridWorld } from "../api/types";
import { type DemonFilter, demonSummary, filterDemons } from "../lib/demons";
import { exprText } from "../lib/expr";
import { formatNumber, formatRelativeError, formatTruth, nameParts, truthOf } from "../lib/format";
import { type Term, tip } from "../lib/glossary";
import { readNumber } from "../lib/parse";
import { startPoint } from "../lib/world";
import { type ConfirmButton, confirmButton } from "../ui/legacy-confirm";
import { h, options, section, setText } from "../ui/dom";
import { html, nothing, render as renderTemplate } from "lit-html";
import { live } from "lit-html/directives/live.js";
import { repeat } from "lit-html/directives/repeat.js";
import { styleMap } from "lit-html/directives/style-map.js";
import { field, numberInput } from "../ui/legacy-form";

const DEFAULT_ROLLOUTS = 100;
/** Above this many shown demons the table scrolls in its own box and keeps only the rows in sight. */
export const VIRTUAL_FROM = 60;
const ROW_ESTIMATE_PX = 72;
const COLUMNS = 9;

function explained(tag: "th", term: Term, props: Record<string, unknown>, label: string): HTMLElement {
  return h(tag, { ...props, title: tip(term) }, h("span", { class: "term" }, label));
}

/** What every row is drawn from, besides its demon: read once per render. */
interface RowContext {
  state: Readonly<AppState>;
  thesis: Record<string, number>;
  /** the run is finished or failed: the server refuses (409) to change it */
  closed: boolean;
  /** the world offers an evaluation of a demon's question */
  evaluable: boolean;
}

/** The words of a target policy's kind that have a glossary entry of their own; the others (greedy,
 * softmax, ...) are explained by the target policy's. */
const POLICY_TERMS: Partial<Record<string, Term>> = {
  uniform: "uniformPolicy",
  fixed: "fixedPolicy",
  of: "followsPolicy",
};

/** The question under a demon's name: its target policy and cumulant, each word explained in its tooltip. */
function questionOf(demon: Demon) {
  const policy = demon.spec.policy;
  const kind = policy?.kind ?? "uniform";
  const follows = policy?.kind === "of" ? `follows ${policy.demon}` : kind;
  return html`<span class="term" title=${tip(POLICY_TERMS[kind] ?? "policy")}>${follows}</span> ·
    <span class="term" title=${tip("cumulant")}>cumulant</span> ${exprText(demon.spec.cumulant)}`;
}

export function demonTable(app: App, scope: Scope): HTMLElement {
  const rollouts = numberInput(DEFAULT_ROLLOUTS, { name: "rollouts" });
  const evaluateAll = h("button", { type: "button" }, "Evaluate all");
  const evaluationNote = h("p", { class: "hint evaluation-note", dataset: { testid: "evaluation-note" } });
  const evaluationHead = h("span", { class: "term" });
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
  // Each demon's Remove button keeps its own "armed" state across renders, so it is made once per demon.
  const removeButtons = new Map<string, ConfirmButton>();
  const pending = new Set<string>();
  const removing = new Set<string>();

  const evaluate = async (demon: string) => {
    const episodes = readNumber(rollouts.value);
    pending.add(demon);
    render(state(app));
    await attempt(app, async () => {
      await evaluateDemon(app, demon, episodes);
      notify(app, `Evaluated '${demon}' over ${episodes} rollouts.`);
    });
    pending.delete(demon);
    render(state(app));
  };
  // One after the other: the server runs at most two evaluations at once (429 beyond). "All" means the
  // demons the filter shows.
  evaluateAll.addEventListener("click", async () => {
    evaluateAll.disabled = true;
    for (const demon of shownDemons(state(app))) if (!pending.has(demon.name)) await evaluate(demon.name);
    evaluateAll.disabled = false;
  });

  const filterNow = (): DemonFilter => ({ text: search.value, show: show.value as DemonFilter["show"] });
  const shownDemons = (state: Readonly<AppState>): Demon[] =>
    filterDemons(state.demons, filterNow(), state.live?.metrics ?? {}, state.charted);
  search.addEventListener("input", () => render(state(app)));
  show.addEventListener("change", () => render(state(app)));

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
      if (!rendering) render(state(app));
    },
  });
  let rendering = false;
  let currentNames: string[] = [];
  let mounted = false;

  const removeButton = (demon: string): ConfirmButton => {
    let button = removeButtons.get(demon);
    if (!button) {
      // Removing takes two presses, so a stray click cannot throw a demon (and its learning) away.
      button = confirmButton({
        class: "small danger",
        text: (armed) => (removing.has(demon) ? "Removing…" : armed ? "Really remove?" : "Remove"),
        label: (armed) => (armed ? `Really remove ${demon}?` : `Remove ${demon}`),
        onConfirm: () => removeNow(demon),
      });
      removeButtons.set(demon, button);
    }
    return button;
  };

  /** One demon's row: a template that lit-html keeps (by the demon's name) and updates in place. */
  const rowTemplate = (demon: Demon, index: number, { state, thesis, closed, evaluable }: RowContext) => {
    const { evaluations, charted } = state;
    const metrics = state.live?.metrics[demon.name] ?? demon.metrics;
    const prediction = state.live ? state.live.predictions[demon.name] : demon.prediction;
    const evaluation = evaluations[demon.name];
    // Against the exact answer where the world has one (the Monte-Carlo mean is cut at the rollouts' cap).
    const truth = truthOf(evaluation);
    const error = evaluation && truth !== null ? (evaluation.prediction ?? NaN) - truth : null;
    const busy = pending.has(demon.name);
    const remove = removeButton(demon.name);
    remove.button.disabled = closed || removing.has(demon.name);
    remove.refresh();
    // A diverged demon is frozen by the server; its numbers stop, the mark says why.
    return html`<tr data-demon=${demon.name} data-index=${index}>
      <th scope="row">
        <span class="swatch-dot" aria-hidden="true" style=${styleMap({ background: demon.colour })}></span>
        <span class="demon-name"
          >${nameParts(demon.name).map((part, i) => (i === 0 ? part : html`<wbr />${part}`))}</span
        >
        ${demon.control ? html`<span class="tag" title=${tip("control")}>control</span>` : nothing}
        <span class="tag diverged" ?hidden=${!metrics?.diverged} title=${tip("diverged")}>diverged</span>
        <span class="question">${questionOf(demon)}</span>
        <label class="chart-toggle"
          ><input
            type="checkbox"
            aria-label=${`Chart ${demon.name}`}
            .checked=${live(charted.includes(demon.name))}
            @change=${(event: Event) => toggleCharted(app, demon.name, (event.target as HTMLInputElement).checked)}
          />chart</label
        >
      </th>
      <td class="num">${formatNumber(prediction)}</td>
      <td class="num">${formatNumber(evaluation?.prediction)}</td>
      <td class="num">${formatTruth(evaluation)}</td>
      <td class="num">
        <span>${formatNumber(error)}</span
        ><span class="relative">${evaluation ? formatRelativeError(evaluation.prediction, truth) : ""}</span>
      </td>
      <td class="num">${formatNumber(thesis[demon.name])}</td>
      <td class="num">${formatNumber(metrics?.rupee)}</td>
      <td class="num">${formatNumber(metrics?.ude)}</td>
      <td class="num">${formatNumber(metrics?.step_size)}</td>
      <td>
        <div class="row-actions">
          ${
            evaluable
              ? html`<button
                  type="button"
                  class="small"
                  aria-label=${`Evaluate ${demon.name}`}
                  ?disabled=${busy}
                  @click=${() => void evaluate(demon.name)}
                >
                  ${busy ? "Evaluating…" : "Evaluate"}
                </button>`
              : nothing
          }
          ${remove.button}
        </div>
      </td>
    </tr>`;
  };

  const removeNow = (demon: string) => {
    const runId = state(app).selectedRunId;
    if (runId === null) return;
    removing.add(demon);
    render(state(app));
    void attempt(app, async () => {
      await removeDemon(app, runId, demon);
      notify(app, `Removed demon '${demon}' from the run.`);
    }).finally(() => {
      removing.delete(demon);
      render(state(app));
    });
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
    const { run, demons, live } = state;
    empty.hidden = run !== null;
    table.hidden = run === null;
    tools.hidden = run === null;
    if (run === null) return;
    const [x, y] = startPoint(gridWorld(run.spec.world) ?? {});
    const kind = evaluationKind(run);
    const from = { grid: `from the start (${x}, ${y})`, rollouts: "from the agent's state", none: "not here" }[kind];
    setText(caption, `Demons of ${run.name ?? run.id.slice(0, 6)}: evaluated ${from}`);
    setText(
      evaluationHead,
      { grid: "At the start", rollouts: "From the agent's state", none: "No" }[kind] + ": evaluation",
    );
    // Evaluate all is the grid world's (every demon from one start point); the note says what else is offered.
    evaluateAll.hidden = kind !== "grid";
    rollout.hidden = kind === "none";
    evaluationNote.hidden = kind === "grid";
    setText(evaluationNote, run.evaluation?.note ?? "");
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
    const indexOf = new Map(currentNames.map((name, i) => [name, i]));
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
    const context: RowContext = { state, thesis, closed, evaluable: kind !== "none" };
    // Keyed by name: a row's DOM stays while its numbers change 30 times a second, and is moved only
    // when the order changes (a row taken out of the page, even for a moment, loses the focus and the
    // click under way on its buttons).
    renderTemplate(
      html`${topSpacer}${repeat(
        visible,
        (demon) => demon.name,
        (demon) => rowTemplate(demon, indexOf.get(demon.name) ?? 0, context),
      )}${bottomSpacer}`,
      body,
    );
    if (virtual) {
      for (const tr of body.querySelectorAll<HTMLTableRowElement>("tr[data-demon]")) virtualizer.measureElement(tr);
    }
    for (const name of removeButtons.keys()) if (!indexOf.has(name)) removeButtons.delete(name);
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
        h("th", { scope: "colgroup", colspan: 3, class: "group", title: tip("truth") }, evaluationHead),
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

  const rollout = field("Rollouts per evaluation", rollouts, { class: "inline-field", term: "truth" });
  watchState(app, scope, ["run", "demons", "live", "evaluations", "charted"], render);
  render(state(app));

  return section(
    {
      class: "panel demons-panel",
      id: "demons-title",
      title: "Demons",
      beside: [h("div", { class: "row tight" }, rollout, evaluateAll)],
    },
    tools,
    evaluationNote,
    empty,
    scrollBox,
  );
}
