/**
 * The viser live view, embedded: its address comes from GET /api/view, and it shows the run selected
 * in the dashboard (POST /api/view on every selection, see `selectRun`). Where the server runs without
 * it (`enabled: false`; only `horde serve` starts one) a short note stands instead.
 */
import { html } from "lit-html";
import type { App, LiveView } from "../app/app";
import { mount } from "../app/view";
import { heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";

export function viserEmbed(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel viser-panel" aria-labelledby="viser-title"></section>`);
  mount(
    app,
    scope,
    element,
    ["liveView"],
    ({ liveView }) =>
      html`${heading({ id: "viser-title", title: "Live view" })}
        <div class="viser-body">${body(liveView)}</div>`,
  );
  return element;
}

// The frame is kept while the view stays on: it must not reload when only the run it shows changes.
function body(view: LiveView) {
  if (view.state === "unknown") return html`<p class="muted">Looking for the live view…</p>`;
  if (view.state === "off") {
    return html`<p class="note" data-testid="viser-note">
      No live view: ${view.why.replace(/\.$/, "")}. The table and the charts above still follow the run.
    </p>`;
  }
  return html`<iframe
      src=${view.url}
      title="The viser live view of the selected run"
      class="viser-frame"
      allow="fullscreen"
    ></iframe>
    <p class="hint">
      It follows the run selected in the list.
      <a href=${view.url} target="_blank" rel="noopener">Open the live view in its own tab</a>
    </p>`;
}
