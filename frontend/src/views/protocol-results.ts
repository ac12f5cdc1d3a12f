/** A protocol job's results (views/protocol-panel.ts): `horde run`'s table, and the test runs' counts beside the thesis's. */
import { html, nothing } from "lit-html";
import type { Protocol } from "../api/types";
import { tip } from "../lib/glossary";
import { countsTable, protocolSummary, resultRows } from "../lib/protocol";

const HEAD_TIPS: Record<string, string | undefined> = {
  demon: tip("demon"),
  prediction: tip("prediction"),
  "truth (MC) ± se": tip("truth"),
  thesis: tip("thesis"),
};

function head(labels: string[]) {
  return html`<thead>
    <tr>
      ${labels.map((label, i) => {
        const title = HEAD_TIPS[label];
        return title
          ? html`<th scope="col" class=${i ? "num" : ""} title=${title}><span class="term">${label}</span></th>`
          : html`<th scope="col" class=${i ? "num" : ""}>${label}</th>`;
      })}
    </tr>
  </thead>`;
}

export function resultsTables(job: Protocol) {
  const rows = resultRows(job.results ?? []);
  const counts = countsTable(job.results ?? [], job.thesis_counts);
  return html`<h4>Predictions at the start, mean over trials</h4>
    <div class="table-scroll">
      <table class="results-table protocol-table">
        <caption class="visually-hidden">
          Each demon's prediction against the Monte-Carlo truth and the thesis
        </caption>
        ${head(["demon", "prediction", "truth (MC) ± se", "error", "error %", "thesis"])}
        <tbody>
          ${rows.map(
            (row) =>
              html`<tr data-demon=${row.name}>
                <th scope="row">${row.name}</th>
                ${[row.prediction, row.truth, row.error, row.relative, row.thesis].map(
                  (text) => html`<td class="num">${text}</td>`,
                )}
              </tr>`,
          )}
        </tbody>
      </table>
    </div>
    ${
      counts
        ? html`<h4>Greedy test runs of ${counts.demon}: where they ended</h4>
            <div class="table-scroll">
              <table class="counts-table">
                <caption class="visually-hidden">
                  This protocol's test runs beside the thesis's
                </caption>
                ${head(["", "positive terminal", "negative terminal", "none (step limit)"])}
                <tbody>
                  ${counts.rows.map(
                    (row) =>
                      html`<tr data-counts=${row.key}>
                        <th scope="row">${row.label}</th>
                        ${[row.positive, row.negative, row.none].map((text) => html`<td class="num">${text}</td>`)}
                      </tr>`,
                  )}
                </tbody>
              </table>
            </div>`
        : nothing
    }
    <p class="muted protocol-summary">${protocolSummary(job)}</p>`;
}
