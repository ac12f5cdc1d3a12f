/**
 * The Class tab: the teacher's Class panel (issue a student's or a viewer's token, copy its invitation
 * link, list and revoke tokens) and every run on the server as a small live card (its owner, scenario,
 * status and steps, a sparkline of its first demons' predictions), read from GET /api/overview every two
 * seconds while the tab is open; a card opens its run, or presents it on the projector.
 */
import { html, nothing, render as renderTemplate, svg, type TemplateResult } from "lit-html";
import { repeat } from "lit-html/directives/repeat.js";
import { attempt, notify, selectRun } from "../app/actions";
import { mayChange } from "../app/access";
import { queryClient, watchQuery } from "../app/queries";
import type { AppState, AppStore } from "../app/state";
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import type { RunCard, Token, TokenIssued } from "../api/types";
import { formatCount, formatNumber, formatStatus } from "../lib/format";
import { CONFIRM_MS } from "../ui/confirm";

const OVERVIEW_MS = 2000;
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
      ${paths.map((points, i) => svg`<polyline points=${points} fill="none" stroke=${SPARK_COLOURS[i % 3]} stroke-width="2" />`)}
    </svg>
    <figcaption>
      ${names.map((name, i) => html`<span class="spark-key"><span class="swatch-dot" style="background:${SPARK_COLOURS[i % 3]}"></span>${name} ${formatNumber(last(name))}</span>`)}
    </figcaption>
  </figure>`;
}

export function classTab(store: AppStore): HTMLElement {
  const root = document.createElement("div");
  root.className = "class-tab";
  let cards: RunCard[] = [];
  let tokens: Token[] = [];
  let issued: TokenIssued | null = null;
  let copied = false;
  let armed: string | null = null; // the token a second press of Revoke revokes
  let armedTimer: number | undefined;
  let issuing = false;
  let problem = "";

  const open = (card: RunCard, present: boolean) =>
    void attempt(store, async () => {
      await selectRun(store, card.id);
      store.update({ tab: "live", present });
    });

  const loadTokens = async () => {
    if (store.state.me?.role !== "teacher" || !store.state.me.tokens) return;
    tokens = await unwrap(api.GET("/api/tokens"));
    draw();
  };

  const issue = async (event: Event) => {
    event.preventDefault();
    const form = event.target as HTMLFormElement;
    const data = new FormData(form);
    const body = {
      name: String(data.get("name") ?? "").trim(),
      role: data.get("role") === "viewer" ? "viewer" : "student",
    } as const;
    issuing = true;
    problem = "";
    draw();
    try {
      issued = await unwrap(api.POST("/api/tokens", { body }));
      copied = false;
      form.reset();
      await loadTokens();
    } catch (error) {
      problem =
        error instanceof ApiError && error.problems.length > 0
          ? error.problems.map((p) => `${p.loc.at(-1)}: ${p.msg}`).join("; ")
          : errorMessage(error);
    } finally {
      issuing = false;
      draw();
    }
  };

  const copy = async (link: string, input: HTMLInputElement | null) => {
    try {
      await navigator.clipboard.writeText(link);
    } catch {
      input?.select(); // no clipboard outside a secure context: the link is selected for Ctrl+C
      document.execCommand?.("copy");
    }
    copied = true;
    draw();
  };

  const revoke = (token: Token) => {
    if (armed !== token.id) {
      armed = token.id;
      window.clearTimeout(armedTimer);
      armedTimer = window.setTimeout(() => {
        armed = null;
        draw();
      }, CONFIRM_MS);
      draw();
      return;
    }
    armed = null;
    void attempt(store, async () => {
      await unwrap(api.DELETE("/api/tokens/{token_id}", { params: { path: { token_id: token.id } } }));
      if (issued?.id === token.id) issued = null;
      notify(store, `Revoked ${token.name}'s token: it changes nothing from now on.`);
      await loadTokens();
    });
  };

  const classPanel = (state: Readonly<AppState>) => {
    const me = state.me;
    if (me?.role !== "teacher") return nothing;
    if (!me.tokens) {
      return html`<section class="panel class-panel" aria-labelledby="class-title">
        <h2 id="class-title">Class</h2>
        <p class="note">
          This server has no HORDE_TOKEN, so everyone who reaches it is the teacher. Start it with
          <code>HORDE_TOKEN=...</code> to give students tokens of their own: a student then changes only what they
          create, a viewer nothing.
        </p>
      </section>`;
    }
    return html`<section class="panel class-panel needs-teacher" aria-labelledby="class-title">
      <h2 id="class-title">Class</h2>
      <form class="row token-form" @submit=${issue} novalidate aria-label="Issue a token">
        <div class="field">
          <label for="token-name">Name</label>
          <input
            id="token-name"
            name="name"
            maxlength="40"
            required
            autocomplete="off"
            placeholder="a student's name"
          />
        </div>
        <div class="field">
          <label for="token-role">Role</label>
          <select id="token-role" name="role">
            <option value="student">student: creates runs, changes only their own</option>
            <option value="viewer">viewer: watches, changes nothing</option>
          </select>
        </div>
        <div class="submit-cell"><button type="submit" class="primary" ?disabled=${issuing}>Issue a token</button></div>
      </form>
      ${problem ? html`<p class="form-error" role="alert">${problem}</p>` : nothing}
      ${
        issued
          ? html`<div class="invitation" role="status">
              <label for="invitation-link"
                >Invitation for ${issued.name} (${issued.role}): shown once, hand it out now</label
              >
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
                  @click=${() => void copy(issued?.link ?? "", root.querySelector("#invitation-link"))}
                >
                  ${copied ? "Copied" : "Copy the link"}
                </button>
              </div>
            </div>`
          : nothing
      }
      ${
        tokens.length === 0
          ? html`<p class="muted">No tokens yet.</p>`
          : html`<table class="tokens">
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
                        <button
                          type="button"
                          class="danger small"
                          aria-label=${armed === t.id ? `Really revoke ${t.name}'s token?` : `Revoke ${t.name}'s token`}
                          @click=${() => revoke(t)}
                        >
                          ${armed === t.id ? "Really revoke?" : "Revoke"}
                        </button>
                      </td>
                    </tr>`,
                )}
              </tbody>
            </table>`
      }
    </section>`;
  };

  const card = (state: Readonly<AppState>, run: RunCard) =>
    html`<li class="run-card" data-run=${run.id} data-owner=${run.owner}>
      <div class="card-head">
        <h3>${run.name ?? run.id}</h3>
        <span class="badge status-${run.status}">${formatStatus(run.status)}</span>
      </div>
      <p class="card-owner">
        by
        <strong>${run.owner}</strong>${mayChange(state.me, run.owner) && state.me?.role === "student" ? " (yours)" : ""}
      </p>
      <p class="counters">episode ${formatCount(run.episode)} · step ${formatCount(run.step)}</p>
      ${sparkline(run)}
      <div class="row-actions">
        <button
          type="button"
          class="small"
          aria-label=${`Open run ${run.name ?? run.id}`}
          @click=${() => open(run, false)}
        >
          Open
        </button>
        <button
          type="button"
          class="small"
          aria-label=${`Present run ${run.name ?? run.id}`}
          @click=${() => open(run, true)}
        >
          Present
        </button>
      </div>
    </li>`;

  const draw = () => {
    const state = store.state;
    renderTemplate(
      html`${classPanel(state)}
        <section class="panel class-overview" aria-labelledby="overview-title">
          <h2 id="overview-title">Every run</h2>
          ${
            cards.length === 0
              ? html`<p class="muted">No runs on this server yet.</p>`
              : html`<ul class="run-cards" aria-label="Every run on the server">
                  ${repeat(
                    cards,
                    (c) => c.id,
                    (c) => card(state, c),
                  )}
                </ul>`
          }
        </section>`,
      root,
    );
  };

  const overviewWatch = () => ({
    queryKey: ["overview"],
    queryFn: () => unwrap(api.GET("/api/overview")),
    every: OVERVIEW_MS as number | false,
    enabled: store.state.tab === "class",
  });
  const overview = watchQuery(queryClient, overviewWatch(), (read) => {
    cards = read;
    draw();
  });
  store.subscribe(() => {
    overview.update(overviewWatch());
    if (store.state.tab === "class") void attempt(store, loadTokens);
    draw();
  }, ["tab", "me"]);
  draw();
  return root;
}
