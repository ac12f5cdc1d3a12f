/**
 * The results of a run's protocol, like `horde run`'s table: once the run has finished, per demon the
 * prediction at the start state, the Monte-Carlo truth (when evaluated in the demon table) with its
 * error, and the thesis's number. The server keeps no results of the protocol's evaluation and test
 * runs for a live run, so the truth comes from the dashboard's own evaluations.
 */
import { html, nothing } from "lit-html";
import type { App, AppState } from "../app/app";
import { mount } from "../app/view";
import type { Run, Summary } from "../api/types";
import { evaluationKind } from "../api/types";
import { MISSING, formatCount, formatNumber, formatRelativeError, formatTruth, truthOf } from "../lib/format";
import { heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";

export function runResults(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel results-panel" aria-labelledby="results-title"></section>`);
  mount(app, scope, element, ["run", "evaluations"], ({ run, evaluations }) => {
    element.hidden = !run?.summary;
    return html`${heading({ id: "results-title", title: "Results" })}
      <div>${run?.summary ? results(run, run.summary, evaluations) : nothing}</div>`;
  });
  return element;
}

function results(run: Run, summary: Summary, evaluations: AppState["evaluations"]) {
  const thesis = run.spec.thesis ?? {};
  const counts = thesis.counts;
  const grid = evaluationKind(run) === "grid";
  const row = (name: string) => {
    const prediction = summary.predictions[name];
    // Only the grid world's evaluations are from the start, where these predictions are.
    const startTruth = grid ? evaluations[name] : undefined;
    return html`<tr>
      <th scope="row">${name}</th>
      <td class="num">${formatNumber(prediction)}</td>
      <td class="num">${startTruth ? formatTruth(startTruth) : grid ? "evaluate in the table" : MISSING}</td>
      <td class="num">${startTruth ? formatRelativeError(prediction, truthOf(startTruth)) : MISSING}</td>
      <td class="num">${formatNumber(thesis.predictions?.[name])}</td>
    </tr>`;
  };
  return html`<p>
      ${run.status === "failed" ? "Failed" : "Finished"} after ${formatCount(summary.episodes)} episodes
      (${formatCount(summary.steps)} steps)${summary.stopped_early ? ", stopped early by the stopping rule" : ""}; last
      return ${formatNumber(summary.last_return)}.
    </p>
    <table class="results-table">
      <caption class="visually-hidden">
        Predictions at the start state against the truth and the thesis
      </caption>
      <thead>
        <tr>
          <th scope="col">demon</th>
          <th scope="col" class="num">prediction</th>
          <th scope="col" class="num">truth (± se)</th>
          <th scope="col" class="num">error</th>
          <th scope="col" class="num">thesis</th>
        </tr>
      </thead>
      <tbody>
        ${Object.keys(summary.predictions).map(row)}
      </tbody>
    </table>
    ${
      counts
        ? html`<p>
            The thesis's greedy test runs: positive ${counts.positive}, negative ${counts.negative}, none
            ${counts.none}.
            <span class="muted"
              >(A live run does not make test runs: the Protocol tab runs the scenario's protocol with its test
              runs.)</span
            >
          </p>`
        : nothing
    }`;
}
