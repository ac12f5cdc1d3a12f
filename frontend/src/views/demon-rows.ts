/** The demon table's head and rows (views/demon-table.ts): a row is one demon, kept by its name. */
import { html, nothing } from "lit-html";
import { live } from "lit-html/directives/live.js";
import { styleMap } from "lit-html/directives/style-map.js";
import { toggleCharted } from "../app/actions";
import type { App, AppState } from "../app/app";
import type { Demon, EvaluationKind } from "../api/types";
import { exprText } from "../lib/expr";
import { formatNumber, formatRelativeError, formatTruth, truthOf } from "../lib/format";
import { type Term, tip } from "../lib/glossary";
import type { StateErrors } from "../lib/state-errors";
import { type Confirm, confirmButton } from "../ui/confirm";
import { brokenName, term } from "../ui/html";

/** What every row is drawn from, besides its demon: read once per render. */
export interface RowContext {
  app: App;
  state: AppState;
  /** demons being evaluated, and being removed */
  pending: ReadonlySet<string>;
  removing: ReadonlySet<string>;
  /** each demon's Remove keeps its "armed" state across renders */
  confirmOf: (demon: string) => Confirm;
  evaluate: (demon: string) => void;
  remove: (demon: string) => void;
  thesis: Record<string, number>;
  /** the run is finished or failed: the server refuses (409) to change it */
  closed: boolean;
  /** the world offers an evaluation of a demon's question */
  evaluable: boolean;
  /** each demon's latest RMSVE and RMSPBE (their columns); null on a world without discrete states */
  errors: ReadonlyMap<string, StateErrors> | null;
}

/** The words of a target policy's kind that have a glossary entry of their own; the others (greedy,
 * softmax, ...) are explained by the target policy's. */
const POLICY_TERMS: Partial<Record<string, Term>> = {
  uniform: "uniformPolicy",
  fixed: "fixedPolicy",
  of: "followsPolicy",
};

/** The question under a demon's name: its target policy and cumulant, each word explained in its tooltip. */
function questionOf(demon: Demon) {
  const policy = demon.spec.policy;
  const kind = policy?.kind ?? "uniform";
  const follows = policy?.kind === "of" ? `follows ${policy.demon}` : kind;
  return html`${term(POLICY_TERMS[kind] ?? "policy", follows)} · ${term("cumulant", "cumulant")}
  ${exprText(demon.spec.cumulant)}`;
}

const th = (word: Term, label: string, cls = "num") =>
  html`<th scope="col" rowspan="2" class=${cls} title=${tip(word)}><span class="term">${label}</span></th>`;

export function tableHead(kind: EvaluationKind, errors = false) {
  const evaluated = { grid: "At the start", rollouts: "From the agent's state", none: "No" }[kind];
  return html`<thead>
    <tr>
      ${th("demon", "Demon", "")} ${th("prediction", "Prediction now")}
      <th scope="colgroup" colspan="3" class="group" title=${tip("truth")}>
        <span class="term">${evaluated}: evaluation</span>
      </th>
      ${th("thesis", "Thesis")} ${th("rupee", "RUPEE")} ${th("ude", "UDE")}
      ${errors ? html`${th("rmsve", "RMSVE")} ${th("rmspbe", "RMSPBE")}` : nothing} ${th("stepSize", "α now")}
      <th scope="col" rowspan="2"><span class="visually-hidden">Actions</span></th>
    </tr>
    <tr>
      <th scope="col" class="num" title=${tip("prediction")}><span class="term">prediction</span></th>
      <th scope="col" class="num" title=${tip("truth")}><span class="term">truth (± se)</span></th>
      <th scope="col" class="num" title="prediction − truth, and relative to the truth">error</th>
    </tr>
  </thead>`;
}

/** One demon's row: a template that lit-html keeps (by the demon's name) and updates in place. */
export function demonRow(context: RowContext, demon: Demon, index: number) {
  const { app, state, thesis, evaluable } = context;
  const name = demon.name;
  const metrics = state.live?.metrics[name] ?? demon.metrics;
  const prediction = state.live ? state.live.predictions[name] : demon.prediction;
  const evaluation = state.evaluations[name];
  // Against the exact answer where the world has one (the Monte-Carlo mean is cut at the rollouts' cap).
  const truth = truthOf(evaluation);
  const error = evaluation && truth !== null ? (evaluation.prediction ?? NaN) - truth : null;
  const busy = context.pending.has(name);
  // A diverged demon is frozen by the server; its numbers stop, the mark says why.
  return html`<tr data-demon=${name} data-index=${index}>
    <th scope="row">
      <span class="swatch-dot" aria-hidden="true" style=${styleMap({ background: demon.colour })}></span>
      <span class="demon-name">${brokenName(name)}</span>
      ${demon.control ? html`<span class="tag" title=${tip("control")}>control</span>` : nothing}
      <span class="tag diverged" ?hidden=${!metrics?.diverged} title=${tip("diverged")}>diverged</span>
      <span class="question">${questionOf(demon)}</span>
      <label class="chart-toggle"
        ><input
          type="checkbox"
          aria-label=${`Chart ${name}`}
          .checked=${live(state.charted.includes(name))}
          @change=${(event: Event) => toggleCharted(app, name, (event.target as HTMLInputElement).checked)}
        />chart</label
      >
    </th>
    <td class="num">${formatNumber(prediction)}</td>
    <td class="num">${formatNumber(evaluation?.prediction)}</td>
    <td class="num">${formatTruth(evaluation)}</td>
    <td class="num">
      <span>${formatNumber(error)}</span
      ><span class="relative">${evaluation ? formatRelativeError(evaluation.prediction, truth) : ""}</span>
    </td>
    <td class="num">${formatNumber(thesis[name])}</td>
    <td class="num">${formatNumber(metrics?.rupee)}</td>
    <td class="num">${formatNumber(metrics?.ude)}</td>
    ${
      context.errors
        ? html`<td class="num" data-field="rmsve">${formatNumber(context.errors.get(name)?.rmsve)}</td>
            <td class="num" data-field="rmspbe">${formatNumber(context.errors.get(name)?.rmspbe)}</td>`
        : nothing
    }
    <td class="num">${formatNumber(metrics?.step_size)}</td>
    <td>
      <div class="row-actions needs-owner">
        ${
          evaluable
            ? html`<button
                type="button"
                class="small"
                aria-label=${`Evaluate ${name}`}
                ?disabled=${busy}
                @click=${() => context.evaluate(name)}
              >
                ${busy ? "Evaluating…" : "Evaluate"}
              </button>`
            : nothing
        }
        ${removeButton(context, name)}
      </div>
    </td>
  </tr>`;
}

/** Removing takes two presses, so a stray click cannot throw a demon (and its learning) away. */
function removeButton(context: RowContext, name: string) {
  const removing = context.removing.has(name);
  return confirmButton(context.confirmOf(name), {
    class: "small danger",
    text: (armed) => (removing ? "Removing…" : armed ? "Really remove?" : "Remove"),
    label: (armed) => (armed ? `Really remove ${name}?` : `Remove ${name}`),
    disabled: context.closed || removing,
    onConfirm: () => context.remove(name),
  });
}
