/**
 * Keyboard shortcuts (listed in the Help panel): Space start/pause, s step, r reset, c classroom mode,
 * ? help. None fires while the focus is in a field or a select (where the keys are typing), nor with a
 * modifier held; Space is the button's own while the focus is on one.
 */
import type { Scope } from "../ui/scope";
import { attempt, commandRun, stepRun } from "./actions";
import { type App, state } from "./app";

const TYPING = new Set(["INPUT", "SELECT", "TEXTAREA"]);
const PRESSABLE = new Set(["BUTTON", "SUMMARY", "A"]);

export function installShortcuts(app: App, scope: Scope, openHelp: () => void, stepSize: () => number): void {
  scope.listen<KeyboardEvent>(document, "keydown", (event) => {
    if (event.ctrlKey || event.metaKey || event.altKey || event.defaultPrevented) return;
    const target = event.target as HTMLElement | null;
    if (target && (TYPING.has(target.tagName) || target.isContentEditable)) return;
    if (target && PRESSABLE.has(target.tagName) && (event.key === " " || event.key === "Enter")) return;
    if (document.querySelector("dialog[open]") && event.key !== "?") return;
    const { selectedRunId: runId, live, runs, classroom } = state(app);
    const status = live?.status ?? runs.find((r) => r.id === runId)?.status;
    let handled = true;
    if (event.key === "?") openHelp();
    else if (event.key === "c") app.ui.update({ classroom: !classroom });
    else if (runId === null) handled = false;
    else if (event.key === " ") {
      if (status === "running") void attempt(app, () => commandRun(app, runId, "pause"));
      else if (status === "created" || status === "paused") void attempt(app, () => commandRun(app, runId, "start"));
    } else if (event.key === "s") {
      if (status === "created" || status === "paused") void attempt(app, () => stepRun(app, runId, stepSize()));
    } else if (event.key === "r") void attempt(app, () => commandRun(app, runId, "reset"));
    else handled = false;
    if (handled) event.preventDefault();
  });
}
