/** The main area's tabs (Live, Protocol, World editor, Demon editor, Studies): real buttons, arrow keys between them. */
import { html } from "lit-html";
import type { App, Tab } from "../app/app";
import { mount } from "../app/view";
import { host } from "../ui/html";
import type { Scope } from "../ui/scope";

export interface TabPanel {
  tab: Tab;
  label: string;
  /** what the tab shows: an element or a template */
  panel: unknown;
}

export function tabs(app: App, scope: Scope, panels: TabPanel[]): HTMLElement {
  const element = host(html`<div class="tabs"></div>`);
  const choose = (tab: Tab) => app.ui.update({ tab });
  const onKey = (event: KeyboardEvent) => {
    if (event.key !== "ArrowRight" && event.key !== "ArrowLeft") return;
    const index = panels.findIndex(({ tab }) => tab === app.ui.state.tab);
    const next = panels[(index + (event.key === "ArrowRight" ? 1 : panels.length - 1)) % panels.length] as TabPanel;
    choose(next.tab);
    element.querySelector<HTMLButtonElement>(`#tab-${next.tab}`)?.focus();
    event.preventDefault();
  };
  mount(
    app,
    scope,
    element,
    ["tab"],
    ({ tab: shown }) =>
      html`<div role="tablist" aria-label="Views" class="tablist" @keydown=${onKey}>
          ${panels.map(
            ({ tab, label }) =>
              html`<button
                type="button"
                role="tab"
                id="tab-${tab}"
                aria-controls="panel-${tab}"
                aria-selected=${String(tab === shown)}
                tabindex=${tab === shown ? "0" : "-1"}
                @click=${() => choose(tab)}
              >
                ${label}
              </button>`,
          )}
        </div>
        ${panels.map(
          ({ tab, panel }) =>
            html`<div
              role="tabpanel"
              id="panel-${tab}"
              aria-labelledby="tab-${tab}"
              class="tab-panel"
              ?hidden=${tab !== shown}
            >
              ${panel}
            </div>`,
        )}`,
  );
  return element;
}
