/**
 * The Class tab: the teacher's Class panel (issue a student's or a viewer's token, copy its invitation
 * link, list and revoke tokens) and every run on the server as a small live card (its owner, scenario,
 * status and steps, a sparkline of its first demons' predictions), read from GET /api/overview every two
 * seconds while the tab is open; a card opens its run, or presents it on the projector. The cards and the
 * tokens are the query cache's (`keys.overview`, `keys.tokens`); the view keeps only what it shows of its
 * own (the invitation just issued, a revoke armed, the form's state).
 */
import { type TemplateResult, html, nothing, svg } from "lit-html";
import { repeat } from "lit-html/directives/repeat.js";
import { mayChange } from "../app/access";
import { attempt, notify, selectRun } from "../app/actions";
import { type App, type AppState, watchState } from "../app/app";
import { keys, readNow, watchQuery } from "../app/queries";
import { reads } from "../app/reads";
import { mount } from "../app/view";
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import type { Me, RunCard, Token, TokenIssued } from "../api/types";
import { formatCount, formatNumber, formatStatus } from "../lib/format";
import { Confirm, confirmButton } from "../ui/confirm";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";

const OVERVIEW_MS = 2000;
const TOKENS_MS = 5000;
const SPARK_WIDTH = 160;
const SPARK_HEIGHT = 40;
const SPARK_COLOURS = ["#1d4ed8", "#b45309", "#15803d"];

/** The points of each series of a sparkline, each scaled into the box on its own range (a sparkline shows
 * how each prediction moved, as the charts do, each on its own scale); a series of nulls draws nothing. */
export function sparkPaths(card: RunCard, width = SPARK_WIDTH, height = SPARK_HEIGHT): string[] {
  const { steps, series } = card.sparkline;
  if (steps.length < 2) return Object.values(series).map(() => "");
  const [first, last] = [steps[0] as number, steps[steps.length - 1] as number];
  const x = (step: number) => (last > first ? ((step - first) / (last - first)) * width : 0);
  return Object.values(series).map((row) => {
    const finite = row.filter((v): v is number => typeof v === "number" && Number.isFinite(v));
    if (finite.length === 0) return "";
    const [low, high] = [Math.min(...finite), Math.max(...finite)];
    const y = (v: number) => (high > low ? height - 1 - ((v - low) / (high - low)) * (height - 2) : height / 2);
    return row
      .map((v, i) =>
        typeof v === "number" && Number.isFinite(v) ? `${x(steps[i] as number).toFixed(1)},${y(v).toFixed(1)}` : "",
      )
      .filter(Boolean)
      .join(" ");
  });
}

/** What the tab keeps of its own between draws. */
interface ClassLocal {
  app: App;
  draw: () => void;
  /** the token just issued: its invitation link is shown once */
  issued: TokenIssued | null;
  copied: boolean;
  issuing: boolean;
  /** why the last issuing failed */
  problem: string;
  /** each token's Revoke, pressed twice */
  revokes: Map<string, Confirm>;
  revokeOf: (tokenId: string) => Confirm;
}

/** Whether the page may list and issue tokens: the teacher of a server with tokens. */
const issues = (me: Me | null) => me?.role === "teacher" && me.tokens;

export function classTab(app: App, scope: Scope): HTMLElement {
  const element = host(html`<div class="class-tab"></div>`);
  const local: ClassLocal = {
    app,
    draw: () => draw(),
    issued: null,
    copied: false,
    issuing: false,
    problem: "",
    revokes: new Map(),
    revokeOf: (tokenId) => {
      let confirm = local.revokes.get(tokenId);
      if (!confirm) local.revokes.set(tokenId, (confirm = new Confirm(scope, () => draw())));
      return confirm;
    },
  };
  const draw = mount(app, scope, element, ["me", "tab"], (state) => {
    const cards = app.client.getQueryData<RunCard[]>(keys.overview) ?? [];
    const tokens = app.client.getQueryData<Token[]>(keys.tokens) ?? [];
    return html`${classPanel(local, state.me, tokens)} ${overview(local, state, cards)}`;
  });
  // Read while the tab is open (and, for the tokens, only by the teacher of a server with tokens).
  const overviewWatch = () => ({ ...reads.overview(), every: OVERVIEW_MS, enabled: app.ui.state.tab === "class" });
  const tokensWatch = () => ({
    ...reads.tokens(),
    every: TOKENS_MS,
    enabled: app.ui.state.tab === "class" && issues(app.client.getQueryData<Me>(keys.me) ?? null),
  });
  const cards = watchQuery(app.client, overviewWatch(), draw, undefined, scope);
  const tokens = watchQuery(app.client, tokensWatch(), draw, undefined, scope);
  watchState(app, scope, ["me", "tab"], () => {
    cards.update(overviewWatch());
    tokens.update(tokensWatch());
  });
  return element;
}

/** Open a card's run in the Live tab, or present it. */
function open(app: App, card: RunCard, present: boolean): void {
  void attempt(app, async () => {
    await selectRun(app, card.id);
    app.ui.update({ tab: "live", present });
  });
}

/** POST /api/tokens from the form; its invitation is shown once, its 422 under the form. */
async function issue(local: ClassLocal, event: Event): Promise<void> {
  event.preventDefault();
  const form = event.target as HTMLFormElement;
  const data = new FormData(form);
  const body = {
    name: String(data.get("name") ?? "").trim(),
    role: data.get("role") === "viewer" ? "viewer" : "student",
  } as const;
  local.issuing = true;
  local.problem = "";
  local.draw();
  try {
    local.issued = await unwrap(api.POST("/api/tokens", { body }));
    local.copied = false;
    form.reset();
    await readNow(local.app.client, reads.tokens());
  } catch (error) {
    local.problem =
      error instanceof ApiError && error.problems.length > 0
        ? error.problems.map((p) => `${p.loc.at(-1)}: ${p.msg}`).join("; ")
        : errorMessage(error);
  } finally {
    local.issuing = false;
    local.draw();
  }
}

async function copy(local: ClassLocal, link: string, input: HTMLInputElement | null): Promise<void> {
  try {
    await navigator.clipboard.writeText(link);
  } catch {
    input?.select(); // no clipboard outside a secure context: the link is selected for Ctrl+C
    document.execCommand?.("copy");
  }
  local.copied = true;
  local.draw();
}

/** DELETE /api/tokens/{id}: the token changes nothing from now on. */
function revoke(local: ClassLocal, token: Token): void {
  const { app } = local;
  void attempt(app, async () => {
    await unwrap(api.DELETE("/api/tokens/{token_id}", { params: { path: { token_id: token.id } } }));
    if (local.issued?.id === token.id) local.issued = null;
    local.revokes.delete(token.id);
    notify(app, `Revoked ${token.name}'s token: it changes nothing from now on.`);
    await readNow(app.client, reads.tokens());
  });
}

/** The teacher's Class panel; a note on a server without tokens; nothing for anyone else. */
function classPanel(local: ClassLocal, me: Me | null, tokens: Token[]) {
  if (me?.role !== "teacher") return nothing;
  if (!me.tokens) {
    return html`<section class="panel class-panel" aria-labelledby="class-title">
      <h2 id="class-title">Class</h2>
      <p class="note">
        This server has no HORDE_TOKEN, so everyone who reaches it is the teacher. Start it with
        <code>HORDE_TOKEN=...</code> to give students tokens of their own: a student then changes only what they create,
        a viewer nothing.
      </p>
    </section>`;
  }
  return html`<section class="panel class-panel needs-teacher" aria-labelledby="class-title">
    <h2 id="class-title">Class</h2>
    <form class="row token-form" @submit=${(e: Event) => void issue(local, e)} novalidate aria-label="Issue a token">
      <div class="field">
        <label for="token-name">Name</label>
        <input id="token-name" name="name" maxlength="40" required autocomplete="off" placeholder="a student's name" />
      </div>
      <div class="field">
        <label for="token-role">Role</label>
        <select id="token-role" name="role">
          <option value="student">student: creates runs, changes only their own</option>
          <option value="viewer">viewer: watches, changes nothing</option>
        </select>
      </div>
      <div class="submit-cell">
        <button type="submit" class="primary" ?disabled=${local.issuing}>Issue a token</button>
      </div>
    </form>
    ${local.problem ? html`<p class="form-error" role="alert">${local.problem}</p>` : nothing} ${invitation(local)}
    ${tokenTable(local, tokens)}
  </section>`;
}

/** The invitation link of the token just issued, with its copy button. */
function invitation(local: ClassLocal) {
  const issued = local.issued;
  if (issued === null) return nothing;
  return html`<div class="invitation" role="status">
    <label for="invitation-link">Invitation for ${issued.name} (${issued.role}): shown once, hand it out now</label>
    <div class="row tight">
      <input
        id="invitation-link"
        class="wide"
        readonly
        .value=${issued.link}
        @focus=${(e: Event) => (e.target as HTMLInputElement).select()}
      />
      <button
        type="button"
        @click=${(e: Event) => {
          const row = (e.currentTarget as HTMLElement).parentElement;
          void copy(local, issued.link, row?.querySelector("input") ?? null);
        }}
      >
        ${local.copied ? "Copied" : "Copy the link"}
      </button>
    </div>
  </div>`;
}

/** The tokens in use, each with its Revoke (two presses). */
function tokenTable(local: ClassLocal, tokens: Token[]) {
  for (const id of local.revokes.keys()) if (!tokens.some((t) => t.id === id)) local.revokes.delete(id);
  if (tokens.length === 0) return html`<p class="muted">No tokens yet.</p>`;
  return html`<table class="tokens">
    <caption class="visually-hidden">
      Tokens in use
    </caption>
    <thead>
      <tr>
        <th scope="col">Name</th>
        <th scope="col">Role</th>
        <th scope="col">Issued</th>
        <th scope="col"><span class="visually-hidden">Revoke</span></th>
      </tr>
    </thead>
    <tbody>
      ${repeat(
        tokens,
        (t) => t.id,
        (t) =>
          html`<tr data-token=${t.id}>
            <th scope="row">${t.name}</th>
            <td>${t.role}</td>
            <td>${new Date(t.created_at).toLocaleString()}</td>
            <td>
              ${confirmButton(local.revokeOf(t.id), {
                class: "danger small",
                text: (armed) => (armed ? "Really revoke?" : "Revoke"),
                label: (armed) => (armed ? `Really revoke ${t.name}'s token?` : `Revoke ${t.name}'s token`),
                onConfirm: () => revoke(local, t),
              })}
            </td>
          </tr>`,
      )}
    </tbody>
  </table>`;
}

/** Every run on the server, as a card each. */
function overview(local: ClassLocal, state: AppState, cards: RunCard[]) {
  return html`<section class="panel class-overview" aria-labelledby="overview-title">
    <h2 id="overview-title">Every run</h2>
    ${
      cards.length === 0
        ? html`<p class="muted">No runs on this server yet.</p>`
        : html`<ul class="run-cards" aria-label="Every run on the server">
            ${repeat(
              cards,
              (c) => c.id,
              (c) => card(local.app, state.me, c),
            )}
          </ul>`
    }
  </section>`;
}

function card(app: App, me: Me | null, run: RunCard) {
  const name = run.name ?? run.id;
  return html`<li class="run-card" data-run=${run.id} data-owner=${run.owner}>
    <div class="card-head">
      <h3>${name}</h3>
      <span class="badge status-${run.status}">${formatStatus(run.status)}</span>
    </div>
    <p class="card-owner">
      by <strong>${run.owner}</strong>${mayChange(me, run.owner) && me?.role === "student" ? " (yours)" : ""}
    </p>
    <p class="counters">episode ${formatCount(run.episode)} · step ${formatCount(run.step)}</p>
    ${sparkline(run)}
    <div class="row-actions">
      <button type="button" class="small" aria-label=${`Open run ${name}`} @click=${() => open(app, run, false)}>
        Open
      </button>
      <button type="button" class="small" aria-label=${`Present run ${name}`} @click=${() => open(app, run, true)}>
        Present
      </button>
    </div>
  </li>`;
}

function sparkline(card: RunCard): TemplateResult {
  const names = Object.keys(card.sparkline.series);
  const paths = sparkPaths(card);
  const last = (name: string) => card.sparkline.series[name]?.at(-1);
  return html`<figure class="spark">
    <svg
      viewBox="0 0 ${SPARK_WIDTH} ${SPARK_HEIGHT}"
      width=${SPARK_WIDTH}
      height=${SPARK_HEIGHT}
      role="img"
      aria-label=${`Predictions of ${names.join(", ") || "no demon"} over the run's history`}
    >
      ${paths.map(
        (points, i) => svg`<polyline points=${points} fill="none" stroke=${SPARK_COLOURS[i % 3]} stroke-width="2" />`,
      )}
    </svg>
    <figcaption>
      ${names.map(
        (name, i) =>
          html`<span class="spark-key"
            ><span class="swatch-dot" style="background:${SPARK_COLOURS[i % 3]}"></span>${name}
            ${formatNumber(last(name))}</span
          >`,
      )}
    </figcaption>
  </figure>`;
}
