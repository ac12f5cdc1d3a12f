/** The main area's tabs (Live, World editor, Demon editor): real buttons, arrow keys between them. */
import { type App, type Tab, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { h } from "../ui/dom";

export interface TabPanel {
  tab: Tab;
  label: string;
  panel: HTMLElement;
}

export function tabs(app: App, scope: Scope, panels: TabPanel[]): HTMLElement {
  const buttons = panels.map(({ tab, label }) =>
    h(
      "button",
      {
        type: "button",
        role: "tab",
        id: `tab-${tab}`,
        "aria-controls": `panel-${tab}`,
        onclick: () => app.ui.update({ tab }),
      },
      label,
    ),
  );
  const wrappers = panels.map(({ tab, panel }) =>
    h("div", { role: "tabpanel", id: `panel-${tab}`, "aria-labelledby": `tab-${tab}`, class: "tab-panel" }, panel),
  );

  const tablist = h("div", { role: "tablist", "aria-label": "Views", class: "tablist" }, buttons);
  tablist.addEventListener("keydown", (event) => {
    const index = buttons.indexOf(document.activeElement as HTMLButtonElement);
    if (index < 0 || (event.key !== "ArrowRight" && event.key !== "ArrowLeft")) return;
    const next = (index + (event.key === "ArrowRight" ? 1 : buttons.length - 1)) % buttons.length;
    app.ui.update({ tab: (panels[next] as TabPanel).tab });
    buttons[next]?.focus();
    event.preventDefault();
  });

  const render = () => {
    panels.forEach(({ tab }, i) => {
      const selected = state(app).tab === tab;
      buttons[i]?.setAttribute("aria-selected", String(selected));
      buttons[i]?.setAttribute("tabindex", selected ? "0" : "-1");
      (wrappers[i] as HTMLElement).hidden = !selected;
    });
  };
  watchState(app, scope, ["tab"], render);
  render();
  return h("div", { class: "tabs" }, tablist, wrappers);
}
