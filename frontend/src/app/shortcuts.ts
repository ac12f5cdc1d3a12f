/**
 * Keyboard shortcuts (listed in the Help panel): Space start/pause, s step, r reset, c classroom mode,
 * ? help. None fires while the focus is in a field or a select (where the keys are typing), nor with a
 * modifier held; Space is the button's own while the focus is on one.
 */
import { attempt, commandRun, stepRun } from "./actions";
import type { AppStore } from "./state";

const TYPING = new Set(["INPUT", "SELECT", "TEXTAREA"]);
const PRESSABLE = new Set(["BUTTON", "SUMMARY", "A"]);

export function installShortcuts(store: AppStore, openHelp: () => void, stepSize: () => number): void {
  document.addEventListener("keydown", (event) => {
    if (event.ctrlKey || event.metaKey || event.altKey || event.defaultPrevented) return;
    const target = event.target as HTMLElement | null;
    if (target && (TYPING.has(target.tagName) || target.isContentEditable)) return;
    if (target && PRESSABLE.has(target.tagName) && (event.key === " " || event.key === "Enter")) return;
    if (document.querySelector("dialog[open]") && event.key !== "?") return;
    const runId = store.state.selectedRunId;
    const status = store.state.live?.status ?? store.state.runs.find((r) => r.id === runId)?.status;
    let handled = true;
    if (event.key === "?") openHelp();
    else if (event.key === "c") store.update({ classroom: !store.state.classroom });
    else if (runId === null) handled = false;
    else if (event.key === " ") {
      if (status === "running") void attempt(store, () => commandRun(store, runId, "pause"));
      else if (status === "created" || status === "paused")
        void attempt(store, () => commandRun(store, runId, "start"));
    } else if (event.key === "s") {
      if (status === "created" || status === "paused") void attempt(store, () => stepRun(store, runId, stepSize()));
    } else if (event.key === "r") void attempt(store, () => commandRun(store, runId, "reset"));
    else handled = false;
    if (handled) event.preventDefault();
  });
}
