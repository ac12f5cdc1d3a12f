/**
 * Small multiples (uPlot): one chart per charted demon, each with its own y-axis, the demon's prediction
 * (where the agent is) over the steps in its colour, and each evaluation like with like: at the step it
 * was made, a ring for the prediction from the state it was made from (the start, or the agent's state on a
 * world evaluated by rollouts) and a dark dot with its 95 % bar for the truth from that same state (exact on
 * a small lattice world, else the Monte-Carlo mean); the caption gives the latest pair. Evaluated again
 * later, the ring closes in on the dot as the demon learns. Classroom mode charts every demon (up to
 * MAX_MULTIPLES); otherwise the demons ticked in the table. Each chart is sized by its grid cell, never
 * by its content, so the page cannot grow sideways; the fonts follow "Large text". A demon whose values
 * span many powers of ten (`spansDecades`: a diverging one, as TD on Baird's star) is charted on a log
 * (asinh) scale, and its caption says so.
 */
import { html } from "lit-html";
import { ref } from "lit-html/directives/ref.js";
import { repeat } from "lit-html/directives/repeat.js";
import { styleMap } from "lit-html/directives/style-map.js";
import { type App, type AppState, chartedDemons, state, watchState } from "../app/app";
import { followRunRead } from "../app/run-reads";
import { reads } from "../app/reads";
import { mount } from "../app/view";
import type { Evaluation, History } from "../api/types";
import type { EvaluationMark } from "../lib/series";
import { brokenName, heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { type Multiple, drawMultiple, evaluatedFrom } from "./chart-plot";

const REFRESH_MS = 1000;

export function charts(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel charts-panel" aria-labelledby="charts-title"></section>`);
  const multiples = new Map<string, Multiple>();
  const multipleOf = (demon: string) => {
    let multiple = multiples.get(demon);
    if (multiple) return multiple;
    const made: Multiple = { demon, scope: scope.child(), plot: null, key: "", caption: "" };
    made.scope.add(() => made.plot?.destroy());
    multiples.set(demon, made);
    return made;
  };
  const draw = mount(app, scope, element, ["selectedRunId", "charted", "classroom", "demons", "run"], (now) => {
    const names = chartedDemons(now);
    for (const [name, multiple] of multiples) {
      if (names.includes(name)) continue;
      multiple.scope.dispose(); // its plot goes with it
      multiples.delete(name);
    }
    return html`${heading({ id: "charts-title", title: "Predictions over time" })}
      <p class="muted">${note(now, names)}</p>
      <div class="chart-grid">
        ${repeat(
          names,
          (name) => name,
          (name) => figure(multipleOf(name)),
        )}
      </div>`;
  });
  const marks = watchMarks(app, scope);
  watchHistories(app, scope, (read) => {
    for (const history of read) {
      const multiple = multiples.get(history.demon);
      if (multiple?.box) drawMultiple(multiple, history, marks.get(history.demon) ?? [], state(app));
    }
    draw(); // the captions
  });
  // The grid decides each cell's width; the plots follow it (and never the other way round).
  const grid = element.querySelector(".chart-grid");
  if (grid) scope.resized(grid, () => multiples.forEach((m) => m.resize?.()));
  return element;
}

function note(now: AppState, names: string[]): string {
  const all = now.classroom ? now.demons.length : names.length;
  const from = evaluatedFrom(now.run);
  if (names.length === 0)
    return "Tick “chart” under a demon’s name in the table, or switch on classroom mode, to follow it here.";
  if (all > names.length) return `The first ${names.length} of ${all} demons; pick others with “chart” in the table.`;
  return `Each chart has its own scale. Solid: the prediction where the agent is. Each Evaluate marks its step: a ring, the prediction ${from}, and a dark dot with its 95 % bar, the truth ${from}. Evaluate again later: the ring closes in on the dot as the demon learns.`;
}

/** A demon's figure: its caption (the name broken only between words, the latest evaluation) and its plot's box. */
function figure(multiple: Multiple) {
  return html`<figure class="chart" data-demon=${multiple.demon} data-marks=${multiple.marks ?? 0}>
    <figcaption style=${styleMap({ borderLeftColor: multiple.colour ?? "" })}>
      <span class="chart-name">${brokenName(multiple.demon)}</span>${multiple.caption}
    </figcaption>
    <div class="chart-box" ${ref((box) => (multiple.box = box as HTMLElement | undefined))}></div>
  </figure>`;
}

/**
 * Every evaluation of the run shown, by demon, at the step of the weights it evaluated (the charts mark each
 * at its step); two of one step are one mark, the later.
 */
function watchMarks(app: App, scope: Scope): Map<string, EvaluationMark[]> {
  const marks = new Map<string, EvaluationMark[]>();
  let marked: { runId: string | null; evaluations: Record<string, Evaluation> } = { runId: null, evaluations: {} };
  const collect = (now: AppState) => {
    if (now.selectedRunId !== marked.runId) marks.clear();
    for (const [demon, evaluation] of Object.entries(now.evaluations)) {
      const truth = truthLine(evaluation);
      if (evaluation === marked.evaluations[demon] || truth === null) continue;
      // The step of the weights evaluated (an evaluation just after another may read the same copy of them).
      const step = evaluation.step ?? now.live?.step ?? now.run?.step ?? 0;
      marks.set(demon, [...(marks.get(demon) ?? []), { step, prediction: evaluation.prediction, truth }]);
    }
    marked = { runId: now.selectedRunId, evaluations: now.evaluations };
  };
  collect(state(app));
  watchState(app, scope, ["selectedRunId", "evaluations"], collect);
  return marks;
}

/**
 * The charted demons' histories: a query read every second while the run runs, at once when the
 * choice, the run or an evaluation changes, and after a step of a paused run.
 */
function watchHistories(app: App, scope: Scope, onRead: (read: History[]) => void): void {
  const readOf = (now: AppState) => ({
    query: reads.histories(now.selectedRunId ?? "", chartedDemons(now)),
    every: REFRESH_MS,
    enabled: (now.selectedRunId ?? "") !== "" && chartedDemons(now).length > 0 && now.tab === "live",
  });
  const topics = ["selectedRunId", "charted", "tab", "classroom", "demons", "evaluations", "large"] as const;
  followRunRead(app, scope, topics, readOf, onRead);
}

/** The truth to draw: [value, low, high] (low = high = value when exact), or null before an evaluation. */
export function truthLine(evaluation: Evaluation | undefined): [number, number, number] | null {
  if (!evaluation) return null;
  if (evaluation.exact !== null && evaluation.exact !== undefined) {
    return [evaluation.exact, evaluation.exact, evaluation.exact];
  }
  if (evaluation.truth === null || evaluation.truth === undefined) return null;
  const half = 1.96 * (evaluation.stderr ?? 0);
  return [evaluation.truth, evaluation.truth - half, evaluation.truth + half];
}
