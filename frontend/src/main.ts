/** The Horde Lab dashboard's entry: one app (its query cache and UI state), its views and watchers, for the page's life. */
import "./styles.css";
import { attempt, loadCatalog, loadLiveView, loadProtocols } from "./app/actions";
import { createApp } from "./app/app";
import { installShortcuts } from "./app/shortcuts";
import { watchApp } from "./app/watch";
import { Scope } from "./ui/scope";
import { dashboard } from "./views/dashboard";

const app = createApp();
const scope = new Scope();
const { page, help, tour } = dashboard(app, scope);
document.getElementById("app")?.replaceWith(page);
document.body.append(help.element, tour.element);
installShortcuts(app, scope, help.open, () =>
  Number((document.getElementById("step-size") as HTMLSelectElement | null)?.value ?? 1),
);
watchApp(app, scope);
void loadCatalog(app);
void attempt(app, () => loadProtocols(app));
void loadLiveView(app);
