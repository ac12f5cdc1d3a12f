/**
 * The list of runs: status, episode and step of each, its speed, and its commands (start or pause,
 * step, reset, delete); a filter over names, scenarios and ids, and "Delete finished". Rows are kept and
 * updated in place, so the focus stays on a button while the list refreshes.
 */
import { attempt, commandRun, deleteRun, notify, selectRun, setRunSpeed, stepRun } from "../app/actions";
import { type App, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import type { RunBrief } from "../api/types";
import { formatCount, formatHz, formatStatus, runLabel } from "../lib/format";
import { FULL_SPEED, matchesFilter, speedChoice } from "../lib/runs";
import { type ConfirmButton, confirmButton } from "../ui/legacy-confirm";
import { h, options, replaceChildren, section, setText } from "../ui/dom";

const STEP_SIZES = ["1", "10", "100", "1000"];

interface Row {
  item: HTMLLIElement;
  select: HTMLButtonElement;
  status: HTMLElement;
  counters: HTMLElement;
  toggle: HTMLButtonElement;
  step: HTMLButtonElement;
  reset: HTMLButtonElement;
  remove: ConfirmButton;
  speed: HTMLSelectElement;
  fullSpeed: HTMLButtonElement;
  message: HTMLElement;
  run: RunBrief;
}

export function runsPanel(app: App, scope: Scope): HTMLElement {
  const stepSize = h("select", { id: "step-size" }, options(STEP_SIZES, "1"));
  const list = h("ul", { class: "run-list", "aria-label": "Runs" });
  const empty = h("p", { class: "muted" }, "No runs yet: launch a scenario above.");
  const filter = h("input", {
    type: "search",
    id: "run-filter",
    placeholder: "name, scenario, id or status",
    autocomplete: "off",
  });
  const matching = h("p", { class: "hint", "aria-live": "polite" });
  // Deleting every finished (or failed) run takes two presses, as deleting one does.
  const finishedRuns = () => state(app).runs.filter((r) => r.status === "finished" || r.status === "failed");
  const deleteFinished = confirmButton({
    class: "danger small",
    text: (armed) => (armed ? `Really delete ${finishedRuns().length}?` : `Delete finished (${finishedRuns().length})`),
    onConfirm: () => {
      const done = finishedRuns();
      void attempt(app, async () => {
        for (const run of done) await deleteRun(app, run.id);
        notify(app, `Deleted ${done.length} finished run${done.length === 1 ? "" : "s"}.`);
      });
    },
  });
  const rows = new Map<string, Row>();

  const makeRow = (run: RunBrief): Row => {
    const row = {} as Row;
    row.run = run;
    row.select = h("button", {
      type: "button",
      class: "run-select",
      onclick: () => void attempt(app, () => selectRun(app, row.run.id)),
    });
    row.status = h("span", { class: "badge" });
    row.counters = h("span", { class: "counters", dataset: { testid: "run-counters" } });
    row.toggle = h("button", {
      type: "button",
      onclick: () => {
        const command = row.run.status === "running" ? "pause" : "start";
        void attempt(app, () => commandRun(app, row.run.id, command));
      },
    });
    row.step = h("button", {
      type: "button",
      onclick: () => void attempt(app, () => stepRun(app, row.run.id, Number(stepSize.value))),
    });
    row.reset = h(
      "button",
      { type: "button", onclick: () => void attempt(app, () => commandRun(app, row.run.id, "reset")) },
      "Reset",
    );
    // Deleting takes two presses, so a stray click or key cannot throw a run away.
    row.remove = confirmButton({
      text: (armed) => (armed ? "Really delete?" : "Delete"),
      label: (armed) => (armed ? `Really delete run ${runLabel(row.run)}?` : `Delete run ${runLabel(row.run)}`),
      onConfirm: () =>
        void attempt(app, async () => {
          await deleteRun(app, row.run.id);
          notify(app, `Deleted run ${runLabel(row.run)}.`);
        }),
    });
    row.speed = h("select", {
      class: "speed",
      title: "Steps per second: slow enough to watch each step, or as fast as the machine can learn",
      onchange: () => {
        const hz = row.speed.value === FULL_SPEED ? null : Number(row.speed.value);
        void attempt(app, () => setRunSpeed(app, row.run.id, hz));
      },
    });
    row.fullSpeed = h(
      "button",
      {
        type: "button",
        class: "small",
        title: "Learn as fast as the machine can (the live view then shows a sample of the steps)",
        onclick: () => void attempt(app, () => setRunSpeed(app, row.run.id, null)),
      },
      "Full speed",
    );
    row.message = h("p", { class: "run-message", role: "status", hidden: true });
    row.item = h(
      "li",
      { class: "run-item", dataset: { run: run.id } },
      h("div", { class: "run-head" }, row.select, row.status),
      row.counters,
      row.message,
      h("div", { class: "run-speed" }, row.speed, row.fullSpeed),
      h("div", { class: "run-actions" }, row.toggle, row.step, row.reset, row.remove.button),
    );
    return row;
  };

  filter.addEventListener("input", () => render());

  const render = () => {
    const { runs, selectedRunId, live } = state(app);
    empty.hidden = runs.length > 0;
    deleteFinished.button.disabled = finishedRuns().length === 0;
    deleteFinished.refresh();
    const shown = runs.filter((r) => matchesFilter(r, filter.value));
    matching.hidden = filter.value.trim() === "";
    setText(matching, `${shown.length} of ${runs.length} runs match`);
    const seen = new Set<string>();
    for (const brief of shown) {
      seen.add(brief.id);
      // The selected run's stream is fresher than the list's once-a-second reading.
      const run =
        live && live.run === brief.id
          ? {
              ...brief,
              status: live.status,
              step: live.step,
              episode: live.episode,
              hz: live.hz,
              message: live.message,
            }
          : brief;
      let row = rows.get(run.id);
      if (!row) {
        row = makeRow(run);
        rows.set(run.id, row);
      }
      updateRow(row, run, selectedRunId);
      // The server's order; a row is moved only when out of place, since a node taken out of the page,
      // even for a moment, loses the focus and the click under way on its buttons.
      const at = list.children[seen.size - 1];
      if (at !== row.item) list.insertBefore(row.item, at ?? null);
    }
    for (const [id, row] of rows) {
      if (!seen.has(id)) {
        row.item.remove();
        rows.delete(id);
      }
    }
  };
  watchState(app, scope, ["runs", "selectedRunId", "live"], render);
  render();

  return section(
    {
      class: "panel runs-panel",
      id: "runs-title",
      title: "Runs",
      beside: [h("label", { for: "step-size", class: "inline" }, "Steps per Step ", stepSize)],
    },
    h("div", { class: "run-filter" }, h("label", { for: "run-filter" }, "Filter runs"), filter, matching),
    h("div", { class: "actions" }, deleteFinished.button),
    empty,
    list,
  );
}

function updateRow(row: Row, run: RunBrief, selectedRunId: string | null): void {
  row.run = run;
  const label = runLabel(run);
  const selected = run.id === selectedRunId;
  row.item.classList.toggle("selected", selected);
  setText(row.select, label);
  row.select.setAttribute("aria-pressed", String(selected));
  row.select.title = `Show run ${run.id}`;
  setText(row.status, formatStatus(run.status));
  row.status.className = `badge status-${run.status}`;
  setText(row.counters, `episode ${formatCount(run.episode)} · step ${formatCount(run.step)} · ${formatHz(run.hz)}`);
  // The server's word when it matters: kernels being prepared, or why the run failed.
  const says = run.status === "failed" || run.message.startsWith("preparing") ? run.message : "";
  row.message.hidden = says === "";
  setText(row.message, says);
  const choice = speedChoice(run.hz);
  if (row.speed.dataset.choices !== choice.key) {
    row.speed.dataset.choices = choice.key;
    replaceChildren(row.speed, options(choice.items, choice.value));
  }
  if (document.activeElement !== row.speed) row.speed.value = choice.value;
  row.speed.setAttribute("aria-label", `Speed of run ${label}`);
  row.fullSpeed.disabled = run.hz === null || run.hz === undefined;
  row.fullSpeed.setAttribute("aria-label", `Run ${label} at full speed`);
  const running = run.status === "running";
  const done = run.status === "finished" || run.status === "failed";
  setText(row.toggle, running ? "Pause" : "Start");
  row.toggle.setAttribute("aria-label", `${running ? "Pause" : "Start"} run ${label}`);
  row.toggle.disabled = done;
  row.toggle.className = running ? "" : "primary";
  setText(row.step, "Step");
  row.step.setAttribute("aria-label", `Step run ${label}`);
  row.step.disabled = running || done;
  row.reset.setAttribute("aria-label", `Reset run ${label}`);
  row.remove.refresh();
}
