/** The Help panel: the glossary of the Horde's words and the keyboard shortcuts, in a modal dialog. */
import { html, render } from "lit-html";
import { GLOSSARY, type Entry, SHORTCUTS } from "../lib/glossary";
import { host } from "../ui/html";

export interface Help {
  element: HTMLDialogElement;
  open: () => void;
}

export function help(): Help {
  const element = host<HTMLDialogElement>(html`<dialog class="help" aria-labelledby="help-title"></dialog>`);
  const entries: Entry[] = Object.values(GLOSSARY);
  render(
    html`<div class="panel-head">
        <h2 id="help-title">Help: words and keys</h2>
        <button type="button" class="small" @click=${() => element.close()}>Close</button>
      </div>
      <p class="hint">
        Hover over (or focus) a dotted word anywhere on the page for its meaning. The Horde: Sutton et al. (2011); the
        measures: White (2015).
      </p>
      <h3>Keyboard shortcuts</h3>
      <table class="shortcuts">
        <caption class="visually-hidden">
          Keyboard shortcuts
        </caption>
        <tbody>
          ${SHORTCUTS.map(
            ([key, what]) =>
              html`<tr>
                <th scope="row"><kbd>${key}</kbd></th>
                <td>${what}</td>
              </tr>`,
          )}
        </tbody>
      </table>
      <h3>Glossary</h3>
      <dl class="glossary">
        ${entries.map(
          (e) =>
            html`<dt>${e.term}</dt>
              <dd>${e.text}</dd>`,
        )}
      </dl>`,
    element,
  );
  // A click on the backdrop (outside the dialog's box) closes it too.
  element.addEventListener("click", (event) => {
    if (event.target === element) element.close();
  });
  return { element, open: () => (element.open ? undefined : element.showModal()) };
}
