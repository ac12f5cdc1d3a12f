/**
 * The Horde Lab dashboard: runs and the scenario launcher on the left; the live demon table, results,
 * charts and the viser view, the protocol runner, the world editor and the demon editor in tabs on the right.
 */
import "./styles.css";
import { attempt, loadCatalog, loadLiveView, loadProtocols } from "./app/actions";
import { createStore } from "./app/state";
import { installShortcuts } from "./app/shortcuts";
import { watchChartedForView, watchProtocol, watchRuns, watchSelectedRun } from "./app/watch";
import { h } from "./ui/dom";
import { charts } from "./views/charts";
import { demonEditor } from "./views/demon-editor";
import { demonOverview } from "./views/demon-overview";
import { demonTable } from "./views/demon-table";
import { header } from "./views/header";
import { help } from "./views/help";
import { labPanel } from "./views/lab-panel";
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

const store = createStore();
const helpPanel = help();
const guide = tour(store);
const streams = streamRuns(store);

const live = h(
  "div",
  { class: "live" },
  liveToolbar(store, guide.start),
  streams.strip,
  demonTable(store),
  demonOverview(store),
  runResults(store),
  h("div", { class: "live-bottom" }, viserEmbed(store), charts(store)),
);

const app = h(
  "div",
  { class: "app" },
  h("a", { href: "#main", class: "skip-link" }, "Skip to the main view"),
  header(store, helpPanel.open),
  h(
    "div",
    { class: "layout" },
    h("aside", { class: "sidebar", "aria-label": "Runs" }, launcher(store), runsPanel(store), streams.list),
    h(
      "main",
      { id: "main", tabindex: "-1" },
      tabs(store, [
        { tab: "live", label: "Live", panel: live },
        { tab: "protocol", label: "Protocol", panel: protocolPanel(store) },
        { tab: "world", label: "World editor", panel: worldEditor(store) },
        { tab: "demon", label: "Demon editor", panel: demonEditor(store) },
        { tab: "studies", label: "Studies", panel: studiesPanel(store) },
        { tab: "lab", label: "Lab", panel: labPanel(store) },
      ]),
    ),
  ),
);

document.getElementById("app")?.replaceWith(app);
document.body.append(helpPanel.element, guide.element);
installShortcuts(store, helpPanel.open, () =>
  Number((document.getElementById("step-size") as HTMLSelectElement | null)?.value ?? 1),
);
void loadCatalog(store);
void attempt(store, () => loadProtocols(store));
void loadLiveView(store);
watchRuns(store);
watchSelectedRun(store);
watchProtocol(store);
watchChartedForView(store);
