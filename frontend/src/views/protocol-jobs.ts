/**
 * Every protocol job the server keeps, one row per demon, beside the thesis's numbers: sortable by any
 * column (click its head; again to reverse), by default only the demons the thesis reports.
 */
import { type App, type AppState, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { formatEstimate, formatNumber } from "../lib/format";
import { tip } from "../lib/glossary";
import { type JobRow, type SortKey, jobRows, sortRows } from "../lib/protocol-jobs";
import { h, replaceChildren, section, setText } from "../ui/dom";

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

export function jobsTable(app: App, scope: Scope): HTMLElement {
  let sortKey: SortKey = "finished";
  let ascending = false;
  const thesisOnly = h("input", { type: "checkbox", id: "jobs-thesis-only", checked: true });
  const count = h("p", { class: "hint" });
  const heads = COLUMNS.map(([key, label, title]) => {
    // The arrow is no part of the button's name (aria-sort on the column head says the order).
    const arrow = h("span", { class: "arrow", "aria-hidden": "true" });
    const button = h("button", { type: "button", class: "sort", title: title || undefined }, label, arrow);
    button.addEventListener("click", () => {
      ascending = sortKey === key ? !ascending : key === "scenario" || key === "demon";
      sortKey = key;
      render(state(app));
    });
    return {
      key,
      arrow,
      th: h("th", { scope: "col", class: key === "scenario" || key === "demon" ? "" : "num" }, button),
    };
  });
  const body = h("tbody", {});
  const table = h(
    "table",
    { class: "jobs-table" },
    h("caption", { class: "visually-hidden" }, "Every protocol job's results beside the thesis's numbers"),
    h(
      "thead",
      {},
      h(
        "tr",
        {},
        heads.map((c) => c.th),
      ),
    ),
    body,
  );
  const element = section(
    { class: "protocol-jobs", id: "jobs-title", title: "Every job's results", level: "h3" },
    h(
      "div",
      { class: "row tight" },
      h(
        "div",
        { class: "field checkbox" },
        thesisOnly,
        h("label", { for: "jobs-thesis-only" }, "only the demons the thesis reports"),
      ),
      count,
    ),
    h("div", { class: "table-scroll" }, table),
  );
  thesisOnly.addEventListener("change", () => render(state(app)));

  const row = (r: JobRow) =>
    h(
      "tr",
      { dataset: { job: r.job, demon: r.demon } },
      h("th", { scope: "row" }, r.scenario),
      h("td", {}, r.demon),
      h("td", { class: "num" }, formatNumber(r.prediction)),
      h("td", { class: "num" }, formatEstimate(r.truth, r.stderr)),
      h("td", { class: "num" }, formatNumber(r.error)),
      h("td", { class: "num" }, formatNumber(r.thesis)),
      h("td", { class: "num" }, formatNumber(r.offThesis)),
      h("td", { class: "num" }, r.finished.replace("T", " ").slice(0, 19)),
    );

  const render = ({ protocols }: Readonly<AppState>) => {
    const rows = sortRows(jobRows(protocols, thesisOnly.checked), sortKey, ascending);
    element.hidden = protocols.every((j) => !j.results);
    const jobs = protocols.filter((j) => j.results).length;
    setText(count, `${rows.length} rows from ${jobs} job${jobs === 1 ? "" : "s"}`);
    for (const head of heads) {
      head.th.setAttribute("aria-sort", head.key === sortKey ? (ascending ? "ascending" : "descending") : "none");
      setText(head.arrow, head.key === sortKey ? (ascending ? " ▲" : " ▼") : "");
    }
    replaceChildren(body, rows.map(row));
  };
  watchState(app, scope, ["protocols"], render);
  render(state(app));
  return element;
}
