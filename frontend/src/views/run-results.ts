/**
 * The results of a run's protocol, like `horde run`'s table: once the run has finished, per demon the
 * prediction at the start state, the Monte-Carlo truth (when evaluated in the demon table) with its
 * error, and the thesis's number. The server keeps no results of the protocol's evaluation and test
 * runs for a live run, so the truth comes from the dashboard's own evaluations.
 */
import { type App, type AppState, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { evaluationKind } from "../api/types";
import { MISSING, formatCount, formatNumber, formatRelativeError, formatTruth, truthOf } from "../lib/format";
import { h, replaceChildren, section } from "../ui/dom";

export function runResults(app: App, scope: Scope): HTMLElement {
  const body = h("div", {});
  const element = section({ class: "panel results-panel", id: "results-title", title: "Results", hidden: true }, body);

  const render = ({ run, evaluations }: Readonly<AppState>) => {
    const summary = run?.summary;
    element.hidden = !run || !summary;
    if (!run || !summary) return;
    const thesis = run.spec.thesis ?? {};
    const names = Object.keys(summary.predictions);
    const counts = thesis.counts;
    const grid = evaluationKind(run) === "grid";
    replaceChildren(
      body,
      h(
        "p",
        {},
        `${run.status === "failed" ? "Failed" : "Finished"} after ${formatCount(summary.episodes)} episodes (${formatCount(summary.steps)} steps)`,
        summary.stopped_early ? ", stopped early by the stopping rule" : "",
        `; last return ${formatNumber(summary.last_return)}.`,
      ),
      h(
        "table",
        { class: "results-table" },
        h("caption", { class: "visually-hidden" }, "Predictions at the start state against the truth and the thesis"),
        h(
          "thead",
          {},
          h(
            "tr",
            {},
            ...["demon", "prediction", "truth (± se)", "error", "thesis"].map((label, i) =>
              h("th", { scope: "col", class: i ? "num" : "" }, label),
            ),
          ),
        ),
        h(
          "tbody",
          {},
          names.map((name) => {
            const prediction = summary.predictions[name];
            // Only the grid world's evaluations are from the start, where these predictions are.
            const startTruth = grid ? evaluations[name] : undefined;
            return h(
              "tr",
              {},
              h("th", { scope: "row" }, name),
              h("td", { class: "num" }, formatNumber(prediction)),
              h(
                "td",
                { class: "num" },
                startTruth ? formatTruth(startTruth) : grid ? "evaluate in the table" : MISSING,
              ),
              h("td", { class: "num" }, startTruth ? formatRelativeError(prediction, truthOf(startTruth)) : MISSING),
              h("td", { class: "num" }, formatNumber(thesis.predictions?.[name])),
            );
          }),
        ),
      ),
      counts
        ? h(
            "p",
            {},
            `The thesis's greedy test runs: positive ${counts.positive}, negative ${counts.negative}, none ${counts.none}. `,
            h(
              "span",
              { class: "muted" },
              "(A live run does not make test runs: the Protocol tab runs the scenario's protocol with its test runs.)",
            ),
          )
        : null,
    );
  };
  watchState(app, scope, ["run", "evaluations"], render);
  render(state(app));
  return element;
}
