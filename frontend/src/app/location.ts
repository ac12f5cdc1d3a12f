/**
 * The dashboard's address names the selected run and tab (`/?run=ID&tab=live`), so a reload, the back
 * button and a shared link restore them. Each change of either pushes a history entry; going back (or
 * opening a link) selects what the address names. A link to a run this server does not have opens the
 * dashboard as it is, with a notice saying so.
 *
 * An invitation link carries a token (`/?token=...`, from the teacher's Class panel): it is kept for this
 * tab (api/token.ts) and dropped from the address at once, so it is neither shown nor shared further.
 */
import { ApiError } from "../api/client";
import { writeToken } from "../api/token";
import type { Scope } from "../ui/scope";
import { attempt, notify, selectRun } from "./actions";
import { type App, TABS, type Tab } from "./app";

/** Take the token of an invitation link, if the address carries one, and drop it from the address. */
export function takeInvitation(): boolean {
  const params = new URLSearchParams(location.search);
  const token = params.get("token");
  if (token === null) return false;
  writeToken(token.trim());
  params.delete("token");
  const rest = params.toString();
  history.replaceState(null, "", `${location.pathname}${rest ? `?${rest}` : ""}`);
  return true;
}

function addressOf(runId: string | null, tab: Tab): string {
  const params = new URLSearchParams();
  if (runId !== null) params.set("run", runId);
  params.set("tab", tab);
  return `${location.pathname}?${params}`;
}

async function followAddress(app: App): Promise<void> {
  const params = new URLSearchParams(location.search);
  const tab = params.get("tab");
  if (tab !== null && (TABS as readonly string[]).includes(tab)) app.ui.update({ tab: tab as Tab });
  const runId = params.get("run");
  if (runId === null || runId === app.ui.state.selectedRunId) return;
  try {
    await selectRun(app, runId);
  } catch (error) {
    if (!(error instanceof ApiError && (error.status === 404 || error.status === 422))) throw error;
    notify(
      app,
      `No run "${runId}" on this server: the link is old, or the run was deleted. Choose one in the list.`,
      "error",
    );
  }
}

/** Select what the address names now, then keep the address naming the selection, until `scope` goes. */
export function keepAddress(app: App, scope: Scope): void {
  let following = false; // true while the address is being applied: that is no new history entry
  const follow = async () => {
    following = true;
    try {
      await attempt(app, () => followAddress(app));
    } finally {
      following = false;
      if (!scope.disposed) history.replaceState(null, "", addressOf(app.ui.state.selectedRunId, app.ui.state.tab));
    }
  };
  scope.add(
    app.ui.subscribe(
      ({ selectedRunId, tab }) => {
        const address = addressOf(selectedRunId, tab);
        if (following || address === `${location.pathname}${location.search}`) return;
        history.pushState(null, "", address);
      },
      ["selectedRunId", "tab"],
    ),
  );
  scope.listen(window, "popstate", () => void follow());
  void follow();
}
