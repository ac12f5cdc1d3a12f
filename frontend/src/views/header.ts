/**
 * The top bar: the title, the selected run's status, episode and step (from its stream) and owner, the
 * notice line, a "large text" switch for projectors, who the page acts as, and the token field for servers
 * that require one (`onToken` is told when it changes).
 */
import { html } from "lit-html";
import type { App, AppState } from "../app/app";
import { mount } from "../app/view";
import { readToken, writeToken } from "../api/token";
import { formatCount, formatNumber, formatStatus, runLabel } from "../lib/format";
import { readFlag, writeFlag } from "../lib/stored";
import { tip } from "../lib/glossary";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";

const LARGE_KEY = "horde-lab-large-text";

export function header(app: App, scope: Scope, openHelp: () => void, onToken: () => void = () => {}): HTMLElement {
  const element = host(html`<header class="topbar"></header>`);
  const setLarge = (on: boolean) => {
    document.documentElement.classList.toggle("large", on);
    app.ui.update({ large: on });
    writeFlag(LARGE_KEY, on);
  };
  setLarge(readFlag(LARGE_KEY));
  mount(
    app,
    scope,
    element,
    ["run", "live", "runs", "selectedRunId", "notice", "large", "me"],
    (state) =>
      html`<h1>Horde Lab</h1>
        ${runStatus(state)} ${notice(state)}
        <div class="tools">
          <button type="button" aria-keyshortcuts="?" @click=${openHelp}>Help (?)</button>
          <button type="button" aria-pressed=${String(state.large)} @click=${() => setLarge(!app.ui.state.large)}>
            Large text
          </button>
          ${role(state)}
          <details class="token">
            <summary>Token</summary>
            <label for="token">Bearer token for changes</label>
            <input
              type="password"
              autocomplete="off"
              id="token"
              placeholder="HORDE_TOKEN"
              .value=${readToken()}
              @change=${(event: Event) => {
                writeToken((event.target as HTMLInputElement).value.trim());
                onToken();
              }}
            />
          </details>
        </div>`,
  );
  return element;
}

/** The selected run's name, status, episode, step and returns, as fresh as its stream. */
function runStatus({ run, live, runs, selectedRunId }: AppState) {
  const brief = runs.find((r) => r.id === selectedRunId);
  const current = live?.status ?? brief?.status ?? run?.status;
  const message = live?.message ?? brief?.message ?? run?.message ?? "";
  const preparing = message.startsWith("preparing");
  // The return of the episode under way, and of the last one that ended (the Results' "last return").
  const last = live?.last_return ?? run?.summary?.last_return;
  const under = live && (current === "running" || current === "paused") ? live.episode_return : null;
  const hasUnder = under !== null && under !== undefined;
  const hasLast = last !== null && last !== undefined;
  // Kept, not rebuilt, as the stream updates them: a tooltip being read stays up.
  return html`<div class="run-status" aria-label="Selected run" ?hidden=${run === null}>
    <span class="run-name">${run ? runLabel(run) : ""}</span>
    <span class="run-owner" data-testid="selected-owner">${run ? `by ${run.owner}` : ""}</span>
    <span class="badge status-${current}">${current ? formatStatus(current) : ""}</span>
    <span data-testid="episode">episode ${formatCount(live?.episode ?? brief?.episode ?? run?.episode)}</span>
    <span data-testid="step">step ${formatCount(live?.step ?? brief?.step ?? run?.step)}</span>
    <span
      ><span class="term" title=${tip("returnSoFar")} ?hidden=${!hasUnder}
        >${hasUnder ? `return so far ${formatNumber(under, 2)}` : ""}</span
      ><span ?hidden=${!(hasUnder && hasLast)}> · </span
      ><span class="term" title=${tip("lastReturn")} ?hidden=${!hasLast}
        >${hasLast ? `last return ${formatNumber(last, 3)}` : ""}</span
      ></span
    >
    <span class="run-says" data-testid="run-says" ?hidden=${!preparing}>${preparing ? `${message}…` : ""}</span>
  </div>`;
}

/** Who the page acts as (GET /api/me); hidden for the teacher of a server without tokens (everyone is). */
function role({ me }: AppState) {
  const who = me === null ? "" : me.name === me.role ? me.role : `${me.name ?? ""} (${me.role})`;
  return html`<span class="role" data-testid="role" ?hidden=${me === null || (me.role === "teacher" && !me.tokens)}
    >${me?.role === "anonymous" ? "read-only (no token)" : who}</span
  >`;
}

/** The notice line: what the last action did, or why it failed (an alert). */
function notice({ notice: message }: AppState) {
  return html`<p
    class="notice ${message?.kind ?? ""}"
    role=${message?.kind === "error" ? "alert" : "status"}
    ?hidden=${message === null}
  >
    ${message?.text ?? ""}
  </p>`;
}
