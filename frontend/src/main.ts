/** The Horde Lab dashboard's entry: one app (its query cache and UI state), its views and watchers, for the page's life. */
import "./styles.css";
import { keepRoleStyles, loadMe } from "./app/access";
import { attempt, loadCatalog, loadLiveView, loadProtocols } from "./app/actions";
import { createApp } from "./app/app";
import { keepAddress, takeInvitation } from "./app/location";
import { installShortcuts } from "./app/shortcuts";
import { watchApp } from "./app/watch";
import { Scope } from "./ui/scope";
import { dashboard } from "./views/dashboard";

takeInvitation(); // an invitation link's token, before the first request
const app = createApp();
const scope = new Scope();
const { page, help, tour } = dashboard(app, scope);
document.getElementById("app")?.replaceWith(page);
document.body.append(help.element, tour.element);
installShortcuts(app, scope, help.open, () =>
  Number((document.getElementById("step-size") as HTMLSelectElement | null)?.value ?? 1),
);
keepRoleStyles(app, scope);
watchApp(app, scope);
keepAddress(app, scope);
void attempt(app, () => loadMe(app));
void loadCatalog(app);
void attempt(app, () => loadProtocols(app));
void loadLiveView(app);
