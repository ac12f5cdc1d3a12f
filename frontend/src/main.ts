/**
 * The Horde Lab dashboard: runs and the scenario launcher on the left; the live demon table, results,
 * charts and the viser view, the protocol runner, the world editor and the demon editor in tabs on the right.
 */
import "./styles.css";
import { attempt, loadCatalog, loadLiveView, loadProtocols } from "./app/actions";
import { createApp } from "./app/app";
import { installShortcuts } from "./app/shortcuts";
import { watchApp } from "./app/watch";
import { Scope } from "./ui/scope";
import { h } from "./ui/dom";
import { charts } from "./views/charts";
import { demonEditor } from "./views/demon-editor";
import { demonOverview } from "./views/demon-overview";
import { demonTable } from "./views/demon-table";
import { header } from "./views/header";
import { help } from "./views/help";
import { launcher } from "./views/launcher";
import { liveToolbar } from "./views/live-toolbar";
import { protocolPanel } from "./views/protocol-panel";
import { runResults } from "./views/run-results";
import { runsPanel } from "./views/runs-panel";
import { streamRuns } from "./views/stream-runs";
import { studiesPanel } from "./views/studies-panel";
import { tabs } from "./views/tabs";
import { tour } from "./views/tour";
import { viserEmbed } from "./views/viser-embed";
import { worldEditor } from "./views/world-editor";

const app = createApp();
// The page's views and watchers live as long as the page.
const scope = new Scope();
const helpPanel = help();
const guide = tour(app, scope);
const streams = streamRuns(app, scope);

const live = h(
  "div",
  { class: "live" },
  liveToolbar(app, scope, guide.start),
  streams.strip,
  demonTable(app, scope),
  demonOverview(app, scope),
  runResults(app, scope),
  h("div", { class: "live-bottom" }, viserEmbed(app, scope), charts(app, scope)),
);

const page = h(
  "div",
  { class: "app" },
  h("a", { href: "#main", class: "skip-link" }, "Skip to the main view"),
  header(app, scope, helpPanel.open),
  h(
    "div",
    { class: "layout" },
    h("aside", { class: "sidebar", "aria-label": "Runs" }, launcher(app, scope), runsPanel(app, scope), streams.list),
    h(
      "main",
      { id: "main", tabindex: "-1" },
      tabs(app, scope, [
        { tab: "live", label: "Live", panel: live },
        { tab: "protocol", label: "Protocol", panel: protocolPanel(app, scope) },
        { tab: "world", label: "World editor", panel: worldEditor(app, scope) },
        { tab: "demon", label: "Demon editor", panel: demonEditor(app, scope) },
        { tab: "studies", label: "Studies", panel: studiesPanel(app, scope) },
      ]),
    ),
  ),
);

document.getElementById("app")?.replaceWith(page);
document.body.append(helpPanel.element, guide.element);
installShortcuts(app, scope, helpPanel.open, () =>
  Number((document.getElementById("step-size") as HTMLSelectElement | null)?.value ?? 1),
);
watchApp(app, scope);
void loadCatalog(app);
void attempt(app, () => loadProtocols(app));
void loadLiveView(app);
