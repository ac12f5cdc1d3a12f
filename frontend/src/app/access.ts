/**
 * Who this page acts as, and which controls it therefore shows (the server's rule: runs/access.py).
 *
 * GET /api/me names the role of the page's token: the teacher (HORDE_TOKEN, or everyone on a server without
 * it), a student, a viewer, or anonymous (no token on a server with roles). Views mark their controls, and one
 * style sheet, rewritten when the role changes, hides those the role may not use:
 *
 * - `needs-change` on a control that changes something (launch, save, run a protocol): hidden for a viewer or
 *   an anonymous page;
 * - `needs-owner` on a control that changes one thing (a run's commands, a demon's removal, an evaluation),
 *   inside an element whose `data-owner` names that thing's owner: hidden unless the page is the teacher's or
 *   the owner's;
 * - `needs-teacher` on a control for the teacher alone (issuing tokens, deleting every finished run).
 *
 * A token the server refuses (revoked, or not its own) is dropped, with a notice saying so.
 */
import { ApiError, api, unwrap } from "../api/client";
import { writeToken } from "../api/token";
import type { Me } from "../api/types";
import { notify } from "./actions";
import type { AppStore } from "./state";

/** The style sheet that hides what the role may not use. */
export function roleStyles(me: Me | null): string {
  if (me === null || me.role === "teacher") return "";
  const hidden = "{ display: none !important; }";
  if (me.role !== "student") return `.needs-change, .needs-owner, .needs-teacher ${hidden}`;
  const name = CSS.escape(me.name ?? "");
  return [
    `.needs-teacher ${hidden}`,
    `[data-owner]:not([data-owner="${name}"]) .needs-owner, [data-owner]:not([data-owner="${name}"]).needs-owner ${hidden}`,
  ].join("\n");
}

/** Whether `me` may change a thing owned by `owner` (as the server decides). */
export function mayChange(me: Me | null, owner: string | undefined): boolean {
  if (me === null) return false;
  if (me.role === "teacher") return true;
  return me.role === "student" && owner !== undefined && owner === me.name;
}

/** Ask the server who this page is; a refused token is dropped (and said so), the page then reads only. */
export async function loadMe(store: AppStore): Promise<void> {
  try {
    store.update({ me: await unwrap(api.GET("/api/me")) });
  } catch (error) {
    if (!(error instanceof ApiError && error.status === 401)) throw error;
    writeToken("");
    notify(store, `The server refused this page's token (${error.message}); it now only reads.`, "error");
    store.update({ me: await unwrap(api.GET("/api/me")) });
  }
}

/** Keep the role's style sheet and the page's `data-role` current. */
export function keepRoleStyles(store: AppStore): void {
  const sheet = document.createElement("style");
  sheet.id = "role-styles";
  document.head.append(sheet);
  const apply = () => {
    const { me } = store.state;
    sheet.textContent = roleStyles(me);
    document.documentElement.dataset.role = me?.role ?? "unknown";
  };
  store.subscribe(apply, ["me"]);
  apply();
}
