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
import { attempt, notify, selectRun } from "./actions";
import { type AppStore, TABS, type Tab } from "./state";

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

async function followAddress(store: AppStore): Promise<void> {
  const params = new URLSearchParams(location.search);
  const tab = params.get("tab");
  if (tab !== null && (TABS as readonly string[]).includes(tab)) store.update({ tab: tab as Tab });
  const runId = params.get("run");
  if (runId === null || runId === store.state.selectedRunId) return;
  try {
    await selectRun(store, runId);
  } catch (error) {
    if (!(error instanceof ApiError && (error.status === 404 || error.status === 422))) throw error;
    notify(
      store,
      `No run "${runId}" on this server: the link is old, or the run was deleted. Choose one in the list.`,
      "error",
    );
  }
}

/** Select what the address names now, then keep the address naming the selection. */
export function keepAddress(store: AppStore): void {
  let following = false; // true while the address is being applied: that is no new history entry
  const follow = async () => {
    following = true;
    try {
      await attempt(store, () => followAddress(store));
    } finally {
      following = false;
      history.replaceState(null, "", addressOf(store.state.selectedRunId, store.state.tab));
    }
  };
  store.subscribe(
    ({ selectedRunId, tab }) => {
      const address = addressOf(selectedRunId, tab);
      if (following || address === `${location.pathname}${location.search}`) return;
      history.pushState(null, "", address);
    },
    ["selectedRunId", "tab"],
  );
  window.addEventListener("popstate", () => void follow());
  void follow();
}
