/**
 * Every protocol job the server keeps, one row per demon, beside the thesis's numbers: sortable by any
 * column (click its head; again to reverse), by default only the demons the thesis reports.
 */
import { html } from "lit-html";
import { ifDefined } from "lit-html/directives/if-defined.js";
import { repeat } from "lit-html/directives/repeat.js";
import type { App } from "../app/app";
import { mount } from "../app/view";
import { formatEstimate, formatNumber } from "../lib/format";
import { tip } from "../lib/glossary";
import { type JobRow, type SortKey, jobRows, sortRows } from "../lib/protocol-jobs";
import { heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";

const COLUMNS: [SortKey, string, string][] = [
  ["scenario", "scenario", ""],
  ["demon", "demon", tip("demon")],
  ["prediction", "prediction", tip("prediction")],
  ["truth", "truth (MC) ± se", tip("truth")],
  ["error", "error", "prediction − truth"],
  ["thesis", "thesis", tip("thesis")],
  ["offThesis", "− thesis", "prediction − the thesis's number"],
  ["finished", "finished", "when the job ended (UTC)"],
];

/** The table's own choices: its order, and whether it shows only the demons the thesis reports. */
interface Order {
  key: SortKey;
  ascending: boolean;
  thesisOnly: boolean;
}

export function jobsTable(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="protocol-jobs" aria-labelledby="jobs-title"></section>`);
  const order: Order = { key: "finished", ascending: false, thesisOnly: true };
  const sortBy = (key: SortKey) => {
    order.ascending = order.key === key ? !order.ascending : key === "scenario" || key === "demon";
    order.key = key;
    draw();
  };
  const draw = mount(app, scope, element, ["protocols"], ({ protocols }) => {
    const rows = sortRows(jobRows(protocols, order.thesisOnly), order.key, order.ascending);
    const jobs = protocols.filter((j) => j.results).length;
    element.hidden = jobs === 0;
    return html`${heading({ id: "jobs-title", title: "Every job's results", level: "h3" })}
      <div class="row tight">
        <div class="field checkbox">
          <input
            type="checkbox"
            id="jobs-thesis-only"
            .checked=${order.thesisOnly}
            @change=${(e: Event) => {
              order.thesisOnly = (e.target as HTMLInputElement).checked;
              draw();
            }}
          /><label for="jobs-thesis-only">only the demons the thesis reports</label>
        </div>
        <p class="hint">${rows.length} rows from ${jobs} job${jobs === 1 ? "" : "s"}</p>
      </div>
      <div class="table-scroll">
        <table class="jobs-table">
          <caption class="visually-hidden">
            Every protocol job's results beside the thesis's numbers
          </caption>
          <thead>
            <tr>
              ${COLUMNS.map((column) => head(order, column, sortBy))}
            </tr>
          </thead>
          <tbody>
            ${repeat(rows, (r) => r.key, row)}
          </tbody>
        </table>
      </div>`;
  });
  return element;
}

/** A column's head: a button that sorts by it; the arrow is no part of its name (aria-sort says the order). */
function head(order: Order, [key, label, title]: [SortKey, string, string], sortBy: (key: SortKey) => void) {
  const sorted = order.key === key;
  const arrow = sorted ? (order.ascending ? " ▲" : " ▼") : "";
  return html`<th
    scope="col"
    class=${key === "scenario" || key === "demon" ? "" : "num"}
    aria-sort=${sorted ? (order.ascending ? "ascending" : "descending") : "none"}
  >
    <button type="button" class="sort" title=${ifDefined(title || undefined)} @click=${() => sortBy(key)}>
      ${label}<span class="arrow" aria-hidden="true">${arrow}</span>
    </button>
  </th>`;
}

function row(r: JobRow) {
  return html`<tr data-job=${r.job} data-demon=${r.demon}>
    <th scope="row">${r.scenario}</th>
    <td>${r.demon}</td>
    <td class="num">${formatNumber(r.prediction)}</td>
    <td class="num">${formatEstimate(r.truth, r.stderr)}</td>
    <td class="num">${formatNumber(r.error)}</td>
    <td class="num">${formatNumber(r.thesis)}</td>
    <td class="num">${formatNumber(r.offThesis)}</td>
    <td class="num">${r.finished.replace("T", " ").slice(0, 19)}</td>
  </tr>`;
}
