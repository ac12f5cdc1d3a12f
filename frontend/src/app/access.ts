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
import { html } from "lit-html";
import { ApiError } from "../api/client";
import { writeToken } from "../api/token";
import type { Me } from "../api/types";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { notify } from "./actions";
import { type App, watchState } from "./app";
import { readNow } from "./queries";
import { reads } from "./reads";

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

/**
 * Ask the server who this page is (into the query cache: `keys.me`); a refused token is dropped (and said
 * so), the page then reads only.
 */
export async function loadMe(app: App): Promise<void> {
  try {
    await readNow(app.client, reads.me());
  } catch (error) {
    if (!(error instanceof ApiError && error.status === 401)) throw error;
    writeToken("");
    notify(app, `The server refused this page's token (${error.message}); it now only reads.`, "error");
    await readNow(app.client, reads.me());
  }
}

/** Keep the role's style sheet (in the document's head) and the page's `data-role` current, until `scope` goes. */
export function keepRoleStyles(app: App, scope: Scope): void {
  const sheet = host<HTMLStyleElement>(html`<style id="role-styles"></style>`);
  document.head.append(sheet);
  scope.add(() => {
    sheet.remove();
    delete document.documentElement.dataset.role;
  });
  watchState(app, scope, ["me"], ({ me }) => {
    sheet.textContent = roleStyles(me);
    document.documentElement.dataset.role = me?.role ?? "unknown";
  });
  sheet.textContent = roleStyles(null);
  document.documentElement.dataset.role = "unknown";
}
