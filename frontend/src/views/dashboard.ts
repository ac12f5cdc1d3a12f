/**
 * The whole dashboard: runs and the scenario launcher on the left; the live demon table, results,
 * charts and the viser view, the protocol runner, the world editor, the demon editor and the studies in
 * tabs on the right; the help panel and the guided tour above them. Every view lives in `scope`.
 */
import { html, render } from "lit-html";
import type { App } from "../app/app";
import type { Scope } from "../ui/scope";
import { charts } from "./charts";
import { demonEditor } from "./demon-editor";
import { demonOverview } from "./demon-overview";
import { demonTable } from "./demon-table";
import { header } from "./header";
import { type Help, help } from "./help";
import { launcher } from "./launcher";
import { liveToolbar } from "./live-toolbar";
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
  const live = html`<div class="live">
    ${liveToolbar(app, scope, guide.start)} ${streams.strip} ${demonTable(app, scope)} ${demonOverview(app, scope)}
    ${runResults(app, scope)}
    <div class="live-bottom">${viserEmbed(app, scope)} ${charts(app, scope)}</div>
  </div>`;
  const page = document.createElement("div");
  page.className = "app";
  render(
    html`<a href="#main" class="skip-link">Skip to the main view</a>
      ${header(app, scope, helpPanel.open)}
      <div class="layout">
        <aside class="sidebar" aria-label="Runs">
          ${launcher(app, scope)} ${runsPanel(app, scope)} ${streams.list}
        </aside>
        <main id="main" tabindex="-1">
          ${tabs(app, scope, [
            { tab: "live", label: "Live", panel: live },
            { tab: "protocol", label: "Protocol", panel: protocolPanel(app, scope) },
            { tab: "world", label: "World editor", panel: worldEditor(app, scope) },
            { tab: "demon", label: "Demon editor", panel: demonEditor(app, scope) },
            { tab: "studies", label: "Studies", panel: studiesPanel(app, scope) },
          ])}
        </main>
      </div>`,
    page,
  );
  return { page, help: helpPanel, tour: guide };
}
