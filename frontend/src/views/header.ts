/**
 * The top bar: the title, the selected run's status, episode and step (from its stream), the notice
 * line, a "large text" switch for projectors, and the token field for servers that require one.
 */
import { type App, type AppState, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { readToken, writeToken } from "../api/token";
import { formatCount, formatNumber, formatStatus, runLabel } from "../lib/format";
import { tip } from "../lib/glossary";
import { h, setText } from "../ui/dom";

const LARGE_KEY = "horde-lab-large-text";

export function header(app: App, scope: Scope, openHelp: () => void): HTMLElement {
  const runName = h("span", { class: "run-name" });
  const status = h("span", { class: "badge" });
  const episode = h("span", { dataset: { testid: "episode" } });
  const step = h("span", { dataset: { testid: "step" } });
  // Kept, not rebuilt, as the stream updates them: a tooltip being read stays up.
  const soFar = h("span", { class: "term", title: tip("returnSoFar") });
  const between = h("span", {}, " · ");
  const lastReturn = h("span", { class: "term", title: tip("lastReturn") });
  const ret = h("span", {}, soFar, between, lastReturn);
  const says = h("span", { class: "run-says", dataset: { testid: "run-says" } });
  const runStatus = h(
    "div",
    { class: "run-status", "aria-label": "Selected run" },
    runName,
    status,
    episode,
    step,
    ret,
    says,
  );
  const notice = h("p", { class: "notice", role: "status" });

  const large = h("button", { type: "button", "aria-pressed": "false" }, "Large text");
  const setLarge = (on: boolean) => {
    document.documentElement.classList.toggle("large", on);
    large.setAttribute("aria-pressed", String(on));
    app.ui.update({ large: on });
    try {
      localStorage.setItem(LARGE_KEY, on ? "1" : "");
    } catch {
      // storage disabled: the switch still works for this page
    }
  };
  large.addEventListener("click", () => setLarge(large.getAttribute("aria-pressed") !== "true"));
  let storedLarge = false;
  try {
    storedLarge = localStorage.getItem(LARGE_KEY) === "1";
  } catch {
    // see above
  }
  setLarge(storedLarge);

  const token = h("input", {
    type: "password",
    value: readToken(),
    autocomplete: "off",
    id: "token",
    placeholder: "HORDE_TOKEN",
  });
  token.addEventListener("change", () => writeToken(token.value.trim()));
  const tokenBox = h(
    "details",
    { class: "token" },
    h("summary", {}, "Token"),
    h("label", { for: "token" }, "Bearer token for changes"),
    token,
  );

  const render = ({ run, live, runs, selectedRunId, notice: message }: Readonly<AppState>) => {
    const brief = runs.find((r) => r.id === selectedRunId);
    runStatus.hidden = run === null;
    if (run) {
      setText(runName, runLabel(run));
      const current = live?.status ?? brief?.status ?? run.status;
      setText(status, formatStatus(current));
      status.className = `badge status-${current}`;
      setText(episode, `episode ${formatCount(live?.episode ?? brief?.episode ?? run.episode)}`);
      setText(step, `step ${formatCount(live?.step ?? brief?.step ?? run.step)}`);
      const message = live?.message ?? brief?.message ?? run.message;
      says.hidden = !message.startsWith("preparing");
      setText(says, says.hidden ? "" : `${message}…`);
      // The return of the episode under way, and of the last one that ended (the Results' "last return").
      const last = live?.last_return ?? run.summary?.last_return;
      const under = live && (current === "running" || current === "paused") ? live.episode_return : null;
      const hasUnder = under !== null && under !== undefined;
      const hasLast = last !== null && last !== undefined;
      setText(soFar, hasUnder ? `return so far ${formatNumber(under, 2)}` : "");
      setText(lastReturn, hasLast ? `last return ${formatNumber(last, 3)}` : "");
      soFar.hidden = !hasUnder;
      lastReturn.hidden = !hasLast;
      between.hidden = !(hasUnder && hasLast);
    }
    notice.hidden = message === null;
    if (message) {
      setText(notice, message.text);
      notice.className = `notice ${message.kind}`;
      notice.setAttribute("role", message.kind === "error" ? "alert" : "status");
    }
  };
  watchState(app, scope, ["run", "live", "runs", "selectedRunId", "notice"], render);
  render(state(app));

  return h(
    "header",
    { class: "topbar" },
    h("h1", {}, "Horde Lab"),
    runStatus,
    notice,
    h(
      "div",
      { class: "tools" },
      h("button", { type: "button", onclick: openHelp, "aria-keyshortcuts": "?" }, "Help (?)"),
      large,
      tokenBox,
    ),
  );
}
