/**
 * The whole dashboard: runs and the scenario launcher on the left; the live demon table, results,
 * charts and the viser view, the class overview, the protocol runner, the world editor, the demon editor and
 * the studies in tabs on the right; the help panel, the guided tour and present mode's exit above them.
 * Every view lives in `scope`.
 */
import { html, render } from "lit-html";
import { loadMe } from "../app/access";
import { attempt, showInLiveView } from "../app/actions";
import { type App, type AppState, state, watchState } from "../app/app";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { charts } from "./charts";
import { classTab } from "./class-tab";
import { demonEditor } from "./demon-editor";
import { demonOverview } from "./demon-overview";
import { demonTable } from "./demon-table";
import { header } from "./header";
import { type Help, help } from "./help";
import { launcher } from "./launcher";
import { liveToolbar } from "./live-toolbar";
import { presentMode } from "./present";
import { protocolPanel } from "./protocol-panel";
import { runResults } from "./run-results";
import { runsPanel } from "./runs-panel";
import { streamRuns } from "./stream-runs";
import { studiesPanel } from "./studies-panel";
import { tabs } from "./tabs";
import { type Tour, tour } from "./tour";
import { viserEmbed } from "./viser-embed";
import { worldEditor } from "./world-editor";

export interface Dashboard {
  /** the page: the top bar, the sidebar and the tabs */
  page: HTMLElement;
  help: Help;
  tour: Tour;
}

export function dashboard(app: App, scope: Scope): Dashboard {
  const helpPanel = help();
  const guide = tour(app, scope);
  const streams = streamRuns(app, scope);
  const live = host(html`<div class="live"></div>`);
  render(
    html`${liveToolbar(app, scope, guide.start)} ${streams.strip} ${demonTable(app, scope)} ${demonOverview(app, scope)}
      ${runResults(app, scope)}
      <div class="live-bottom">${viserEmbed(app, scope)} ${charts(app, scope)}</div>`,
    live,
  );
  const demonPanel = demonEditor(app, scope);
  markOwner(app, scope, [live, demonPanel]);
  const page = document.createElement("div");
  page.className = "app";
  render(
    html`<a href="#main" class="skip-link">Skip to the main view</a>
      ${presentMode(app, scope)} ${header(app, scope, helpPanel.open, () => tokenChanged(app))}
      <div class="layout">
        <aside class="sidebar" aria-label="Runs">
          ${launcher(app, scope)} ${runsPanel(app, scope)} ${streams.list}
        </aside>
        <main id="main" tabindex="-1">
          ${tabs(app, scope, [
            { tab: "live", label: "Live", panel: live },
            { tab: "class", label: "Class", panel: classTab(app, scope) },
            { tab: "protocol", label: "Protocol", panel: protocolPanel(app, scope) },
            { tab: "world", label: "World editor", panel: worldEditor(app, scope) },
            { tab: "demon", label: "Demon editor", panel: demonPanel },
            { tab: "studies", label: "Studies", panel: studiesPanel(app, scope) },
          ])}
        </main>
      </div>`,
    page,
  );
  return { page, help: helpPanel, tour: guide };
}

/** Mark `elements` with the selected run's owner, for the controls that change it (app/access.ts: `needs-owner`). */
function markOwner(app: App, scope: Scope, elements: HTMLElement[]): void {
  const mark = ({ run }: AppState) => {
    for (const element of elements) {
      if (run) element.dataset.owner = run.owner;
      else delete element.dataset.owner;
    }
  };
  watchState(app, scope, ["run"], mark);
  mark(state(app));
}

/** The page's token changed: who it is, and what its embedded view may command, follow. */
function tokenChanged(app: App): void {
  void attempt(app, async () => {
    await loadMe(app);
    const selected = app.ui.state.selectedRunId;
    if (selected !== null) await showInLiveView(app, selected);
  });
}
