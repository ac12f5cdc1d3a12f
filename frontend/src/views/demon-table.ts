/**
 * The live demon table of the selected run: per demon its prediction now (at the agent's state), the
 * truth once evaluated (beside the prediction there and the error: from the world's start on the grid world,
 * from the agent's state on a world evaluated by rollouts; a world with no evaluation says why), the
 * thesis's number when the scenario has one, RUPEE, UDE, on a world of discrete states RMSVE and RMSPBE (the
 * latest of the run's history, read every second while it runs), the step size it takes now (α now: adaptive
 * demons tune theirs), and a `diverged` mark; a colour dot and a chart
 * toggle under each name, and an Evaluate and a Remove button per demon (removing takes two presses).
 * Above it a summary (how many demons learn, how many diverged, mean RUPEE) and a filter. At Horde scale
 * the table scrolls in its own box and only the rows in sight exist (@tanstack/virtual-core). The rows
 * are kept by the demon's name (`repeat`): cells are updated in place from the stream.
 */
import { Virtualizer, elementScroll, observeElementOffset, observeElementRect } from "@tanstack/virtual-core";
import { html, render } from "lit-html";
import { type Ref, createRef, ref } from "lit-html/directives/ref.js";
import { repeat } from "lit-html/directives/repeat.js";
import { styleMap } from "lit-html/directives/style-map.js";
import { attempt, evaluateDemon, notify, removeDemon } from "../app/actions";
import { type App, type AppState, state, watchState } from "../app/app";
import { followRunRead } from "../app/run-reads";
import { reads } from "../app/reads";
import type { Demon } from "../api/types";
import { evaluationKind, gridWorld } from "../api/types";
import { type DemonFilter, demonSummary, filterDemons } from "../lib/demons";
import { formatNumber } from "../lib/format";
import { readNumber } from "../lib/parse";
import { MAX_ERROR_DEMONS, type StateErrors } from "../lib/state-errors";
import { startPoint } from "../lib/world";
import { Confirm } from "../ui/confirm";
import { choices, heading, host } from "../ui/html";
import { numberField } from "../ui/form";
import type { Scope } from "../ui/scope";
import { type RowContext, demonRow, tableHead } from "./demon-rows";

const DEFAULT_ROLLOUTS = 100;
/** Above this many shown demons the table scrolls in its own box and keeps only the rows in sight. */
export const VIRTUAL_FROM = 60;
const ROW_ESTIMATE_PX = 72;
const COLUMNS = 9; // and 2 more with RMSVE and RMSPBE
const ERRORS_REFRESH_MS = 1000;
const SHOW: [DemonFilter["show"], string][] = [
  ["all", "all demons"],
  ["learning", "learning"],
  ["diverged", "diverged"],
  ["charted", "charted"],
  ["control", "control demons"],
];

/** The table's own state beside the app's: its filter, the evaluations and removals under way. */
interface Table {
  app: App;
  scope: Scope;
  filter: DemonFilter;
  /** demons being evaluated, and being removed */
  pending: Set<string>;
  removing: Set<string>;
  evaluatingAll: boolean;
  /** each demon's Remove keeps its "armed" state across renders */
  confirms: Map<string, Confirm>;
  rollouts: Ref<HTMLInputElement>;
  scrollBox: Ref<HTMLDivElement>;
  virtualizer: Virtualizer<HTMLDivElement, HTMLTableRowElement>;
  /** the names of the demons shown, in order (the virtualizer's keys) */
  names: string[];
  /** each demon's latest RMSVE and RMSPBE; null where the run records none */
  errors: Map<string, StateErrors> | null;
  draw: () => void;
}

export function demonTable(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel demons-panel" aria-labelledby="demons-title"></section>`);
  let drawing = false;
  const table: Table = {
    app,
    scope,
    filter: { text: "", show: "all" },
    pending: new Set(),
    removing: new Set(),
    evaluatingAll: false,
    confirms: new Map(),
    rollouts: createRef(),
    scrollBox: createRef(),
    virtualizer: new Virtualizer<HTMLDivElement, HTMLTableRowElement>({
      count: 0,
      getScrollElement: () => table.scrollBox.value ?? null,
      estimateSize: () => ROW_ESTIMATE_PX,
      overscan: 8,
      observeElementRect,
      observeElementOffset,
      scrollToFn: elementScroll,
      getItemKey: (index) => table.names[index] ?? index,
      onChange: () => table.draw(),
    }),
    names: [],
    errors: null,
    draw: () => {
      if (drawing || scope.disposed) return;
      drawing = true;
      try {
        render(panel(table, state(app)), element);
        measureRows(table, element);
      } finally {
        drawing = false;
      }
    },
  };
  watchState(app, scope, ["run", "demons", "live", "evaluations", "charted"], table.draw);
  watchErrors(table);
  table.draw();
  // The virtualizer watches the scroll box (its size, its scrolling) until the table goes.
  scope.add(table.virtualizer._didMount());
  return element;
}

/**
 * RMSVE and RMSPBE from the last row of each demon's history: read every second while the run runs, and after
 * a step of a paused one, on a simulated world beyond the grid (evaluated by rollouts: the Gymnasium worlds, of
 * which only the chains and Baird's star record them; the first answer says whether this run does) of at most
 * MAX_ERROR_DEMONS demons.
 */
function watchErrors(table: Table): void {
  const onRead = (errors: Map<string, StateErrors> | null) => {
    table.errors = errors;
    table.draw();
  };
  const readOf = (now: AppState) => {
    const names = now.demons.map((d) => d.name);
    return {
      query: reads.stateErrors(now.selectedRunId ?? "", names),
      every: ERRORS_REFRESH_MS,
      enabled:
        (now.selectedRunId ?? "") !== "" &&
        evaluationKind(now.run) === "rollouts" &&
        names.length > 0 &&
        names.length <= MAX_ERROR_DEMONS &&
        now.tab === "live",
    };
  };
  const clear = () => {
    if (table.errors !== null) onRead(null);
  };
  followRunRead(table.app, table.scope, ["selectedRunId", "run", "demons", "tab"], readOf, onRead, clear);
}

function panel(table: Table, now: AppState) {
  const { run } = now;
  const kind = evaluationKind(run);
  const shown = run ? shownDemons(table, now) : [];
  return html`${heading({ id: "demons-title", title: "Demons", beside: evaluationTools(table, now) })}
    ${run ? tools(table, now) : ""}
    <p class="hint evaluation-note" data-testid="evaluation-note" ?hidden=${run === null || kind === "grid"}>
      ${run?.evaluation?.note ?? ""}
    </p>
    <p class="muted" ?hidden=${run !== null}>Select a run to see its demons.</p>
    <div class="table-scroll ${shown.length > VIRTUAL_FROM ? "virtual" : ""}" ${ref(table.scrollBox)}>
      ${run ? demonsTable(table, now, shown) : ""}
    </div>`;
}

/** The rollouts per evaluation and Evaluate all (the grid world's: every demon from one start point). */
function evaluationTools(table: Table, { run }: AppState) {
  const kind = evaluationKind(run);
  return html`<div class="row tight">
    ${numberField(
      {
        label: "Rollouts per evaluation",
        id: "demon-rollouts",
        class: "inline-field",
        term: "truth",
        hidden: run === null || kind === "none",
      },
      { name: "rollouts", value: DEFAULT_ROLLOUTS, ref: table.rollouts },
    )}
    <button
      type="button"
      class="needs-owner"
      ?hidden=${run === null || kind !== "grid"}
      ?disabled=${table.evaluatingAll}
      @click=${() => void evaluateAll(table)}
    >
      Evaluate all
    </button>
  </div>`;
}

/** The summary of every demon, and the filter. */
function tools(table: Table, { demons, live }: AppState) {
  const totals = demonSummary(demons, live?.metrics ?? {});
  const count = (n: number) => n.toLocaleString("en-US");
  const set = (patch: Partial<DemonFilter>) => {
    table.filter = { ...table.filter, ...patch };
    table.draw();
  };
  return html`<div class="row tight demon-tools">
    <p class="demon-summary" aria-live="off" data-testid="demon-summary">
      ${count(totals.demons)} demons · ${count(totals.learning)} learning · ${count(totals.diverged)} diverged · mean
      RUPEE ${formatNumber(totals.meanRupee)}
    </p>
    <div class="field inline-field">
      <label for="demon-search">Find demons</label>
      <input
        type="search"
        id="demon-search"
        autocomplete="off"
        placeholder="name or question"
        @input=${(e: Event) => set({ text: (e.target as HTMLInputElement).value })}
      />
    </div>
    <div class="field inline-field">
      <label for="demon-show">Show</label>
      <select
        id="demon-show"
        @change=${(e: Event) => set({ show: (e.target as HTMLSelectElement).value as DemonFilter["show"] })}
      >
        ${choices(SHOW, table.filter.show)}
      </select>
    </div>
  </div>`;
}

function shownDemons(table: Table, { demons, live, charted }: AppState): Demon[] {
  return filterDemons(demons, table.filter, live?.metrics ?? {}, charted);
}

/** The rows in sight, and the room of those above and below them, at Horde scale; else every row. */
function rowsInSight(table: Table, shown: Demon[]): { visible: Demon[]; before: number; after: number } {
  const { virtualizer } = table;
  if (shown.length <= VIRTUAL_FROM) return { visible: shown, before: 0, after: 0 };
  if (virtualizer.options.count !== shown.length)
    virtualizer.setOptions({ ...virtualizer.options, count: shown.length });
  virtualizer._willUpdate();
  const items = virtualizer.getVirtualItems();
  return {
    visible: items.map((item) => shown[item.index]).filter((d): d is Demon => d !== undefined),
    before: items[0]?.start ?? 0,
    after: Math.max(0, virtualizer.getTotalSize() - (items.at(-1)?.end ?? 0)),
  };
}

function demonsTable(table: Table, now: AppState, shown: Demon[]) {
  const run = now.run as NonNullable<AppState["run"]>;
  const [x, y] = startPoint(gridWorld(run.spec.world) ?? {});
  const kind = evaluationKind(run);
  const from = { grid: `from the start (${x}, ${y})`, rollouts: "from the agent's state", none: "not here" }[kind];
  table.names = shown.map((d) => d.name);
  const indexOf = new Map(table.names.map((name, i) => [name, i]));
  for (const name of table.confirms.keys()) if (!indexOf.has(name)) table.confirms.delete(name);
  const { visible, before, after } = rowsInSight(table, shown);
  // The server refuses (409) to change a finished or failed run.
  const status = now.live?.status ?? run.status;
  const context: RowContext = {
    app: table.app,
    state: now,
    pending: table.pending,
    removing: table.removing,
    confirmOf: (name) => confirmOf(table, name),
    evaluate: (name) => void evaluate(table, name),
    remove: (name) => removeNow(table, name),
    thesis: run.spec.thesis?.predictions ?? {},
    closed: status === "finished" || status === "failed",
    evaluable: kind !== "none",
    errors: table.errors,
  };
  const spacer = (px: number) =>
    html`<tr class="spacer" aria-hidden="true" ?hidden=${px === 0}>
      <td colspan=${COLUMNS + (table.errors ? 2 : 0)} style=${styleMap({ height: `${px}px` })}></td>
    </tr>`;
  // Keyed by name: a row's DOM stays while its numbers change 30 times a second, and is moved only
  // when the order changes (a row taken out of the page, even for a moment, loses the focus and the
  // click under way on its buttons).
  return html`<table class="demon-table" aria-live="off">
    <caption>
      Demons of ${run.name ?? run.id.slice(0, 6)}: evaluated ${from}
    </caption>
    ${tableHead(kind, table.errors !== null)}
    <tbody>
      ${spacer(before)}${repeat(
        visible,
        (demon) => demon.name,
        (demon) => demonRow(context, demon, indexOf.get(demon.name) ?? 0),
      )}${spacer(after)}
    </tbody>
  </table>`;
}

function confirmOf(table: Table, name: string): Confirm {
  let confirm = table.confirms.get(name);
  if (!confirm) table.confirms.set(name, (confirm = new Confirm(table.scope, () => table.draw())));
  return confirm;
}

function measureRows(table: Table, element: HTMLElement): void {
  if (!table.scrollBox.value?.classList.contains("virtual")) return;
  for (const tr of element.querySelectorAll<HTMLTableRowElement>("tr[data-demon]"))
    table.virtualizer.measureElement(tr);
}

/** Evaluate one demon (Monte-Carlo rollouts on the server); its row says so meanwhile. */
async function evaluate(table: Table, demon: string): Promise<void> {
  const { app } = table;
  const episodes = readNumber(table.rollouts.value?.value ?? "");
  table.pending.add(demon);
  table.draw();
  await attempt(app, async () => {
    await evaluateDemon(app, demon, episodes);
    notify(app, `Evaluated '${demon}' over ${episodes} rollouts.`);
  });
  table.pending.delete(demon);
  table.draw();
}

// One after the other: the server runs at most two evaluations at once (429 beyond). "All" means the
// demons the filter shows.
async function evaluateAll(table: Table): Promise<void> {
  table.evaluatingAll = true;
  for (const demon of shownDemons(table, state(table.app))) {
    if (!table.pending.has(demon.name)) await evaluate(table, demon.name);
  }
  table.evaluatingAll = false;
  table.draw();
}

/** Remove a demon from the run (after the second press of its Remove). */
function removeNow(table: Table, demon: string): void {
  const { app } = table;
  const runId = app.ui.state.selectedRunId;
  if (runId === null) return;
  table.removing.add(demon);
  table.draw();
  void attempt(app, async () => {
    await removeDemon(app, runId, demon);
    notify(app, `Removed demon '${demon}' from the run.`);
  }).finally(() => {
    table.removing.delete(demon);
    table.draw();
  });
}
