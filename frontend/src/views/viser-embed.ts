/**
 * The viser live view, embedded: its URL comes from GET /api/view ({"url": ...}). Where the server
 * offers no such route (its OpenAPI schema does not list it) or it fails, a short note stands instead.
 */
import { h, replaceChildren } from "../ui/dom";

const VIEW_PATH = "/api/view";

/**
 * The view's URL, or why there is none. The route is looked up in /openapi.json first, so that a
 * server without it costs no failed request (which the browser would log as an error).
 */
async function viewUrl(): Promise<{ url: string } | { why: string }> {
  try {
    const schema = (await (await fetch("/openapi.json")).json()) as { paths?: Record<string, unknown> };
    if (!schema.paths || !(VIEW_PATH in schema.paths))
      return { why: "this server does not offer the live view (no GET /api/view)." };
    const response = await fetch(VIEW_PATH);
    if (!response.ok) return { why: `GET /api/view answered ${response.status}.` };
    // Not in the generated types yet: checked here, since the route is newer than schema.d.ts may be.
    const body = (await response.json()) as { url?: unknown };
    return typeof body.url === "string" && body.url ? { url: body.url } : { why: "GET /api/view gave no URL." };
  } catch (error) {
    return { why: `the live view could not be reached (${(error as Error).message}).` };
  }
}

export function viserEmbed(): HTMLElement {
  const body = h("div", { class: "viser-body" }, h("p", { class: "muted" }, "Looking for the live view…"));
  const element = h(
    "section",
    { class: "panel viser-panel", "aria-labelledby": "viser-title" },
    h("h2", { id: "viser-title" }, "Live view"),
    body,
  );
  void viewUrl().then((found) => {
    if ("url" in found) {
      replaceChildren(
        body,
        h("iframe", {
          src: found.url,
          title: "The viser live view of the runs",
          class: "viser-frame",
          allow: "fullscreen",
        }),
        h(
          "p",
          { class: "hint" },
          h("a", { href: found.url, target: "_blank", rel: "noopener" }, "Open the live view in its own tab"),
        ),
      );
    } else {
      replaceChildren(
        body,
        h(
          "p",
          { class: "note", dataset: { testid: "viser-note" } },
          `No live view: ${found.why} The table and the charts above still follow the run.`,
        ),
      );
    }
  });
  return element;
}
