/**
 * The viser live view, embedded: its address comes from GET /api/view, and it shows the run selected
 * in the dashboard (POST /api/view on every selection, see `selectRun`). Where the server runs without
 * it (`enabled: false`; only `horde serve` starts one) a short note stands instead.
 */
import { type App, type AppState, type LiveView, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { h, replaceChildren, section } from "../ui/dom";

export function viserEmbed(app: App, scope: Scope): HTMLElement {
  const body = h("div", { class: "viser-body" });
  const element = section({ class: "panel viser-panel", id: "viser-title", title: "Live view" }, body);

  let shown: LiveView["state"] | null = null;
  const render = ({ liveView }: Readonly<AppState>) => {
    // Built once per state: the frame must not reload when only the run it shows changes.
    if (liveView.state === shown) return;
    shown = liveView.state;
    if (liveView.state === "unknown") {
      replaceChildren(body, h("p", { class: "muted" }, "Looking for the live view…"));
    } else if (liveView.state === "on") {
      replaceChildren(
        body,
        h("iframe", {
          src: liveView.url,
          title: "The viser live view of the selected run",
          class: "viser-frame",
          allow: "fullscreen",
        }),
        h(
          "p",
          { class: "hint" },
          "It follows the run selected in the list. ",
          h("a", { href: liveView.url, target: "_blank", rel: "noopener" }, "Open the live view in its own tab"),
        ),
      );
    } else {
      replaceChildren(
        body,
        h(
          "p",
          { class: "note", dataset: { testid: "viser-note" } },
          `No live view: ${liveView.why.replace(/\.$/, "")}. The table and the charts above still follow the run.`,
        ),
      );
    }
  };
  watchState(app, scope, ["liveView"], render);
  render(state(app));
  return element;
}
