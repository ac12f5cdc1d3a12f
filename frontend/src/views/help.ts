/** The Help panel: the glossary of the Horde's words and the keyboard shortcuts, in a modal dialog. */
import { GLOSSARY, type Entry, SHORTCUTS } from "../lib/glossary";
import { h } from "../ui/dom";

export interface Help {
  element: HTMLDialogElement;
  open: () => void;
}

export function help(): Help {
  const close = h("button", { type: "button", class: "small" }, "Close");
  const entries: Entry[] = Object.values(GLOSSARY);
  const element = h(
    "dialog",
    { class: "help", "aria-labelledby": "help-title" },
    h("div", { class: "panel-head" }, h("h2", { id: "help-title" }, "Help: words and keys"), close),
    h(
      "p",
      { class: "hint" },
      "Hover over (or focus) a dotted word anywhere on the page for its meaning. The Horde: Sutton et al. (2011); the measures: White (2015).",
    ),
    h("h3", {}, "Keyboard shortcuts"),
    h(
      "table",
      { class: "shortcuts" },
      h("caption", { class: "visually-hidden" }, "Keyboard shortcuts"),
      h(
        "tbody",
        {},
        ...SHORTCUTS.map(([key, what]) => h("tr", {}, h("th", { scope: "row" }, h("kbd", {}, key)), h("td", {}, what))),
      ),
    ),
    h("h3", {}, "Glossary"),
    h("dl", { class: "glossary" }, ...entries.flatMap((e) => [h("dt", {}, e.term), h("dd", {}, e.text)])),
  );
  close.addEventListener("click", () => element.close());
  // A click on the backdrop (outside the dialog's box) closes it too.
  element.addEventListener("click", (event) => {
    if (event.target === element) element.close();
  });
  return { element, open: () => (element.open ? undefined : element.showModal()) };
}
