/**
 * How a view is written: a function `(app, scope) => HTMLElement` that renders lit-html templates into
 * its own element with `mount`, which draws it now and again whenever a part of the state it names
 * changes, until its scope goes (then every subscription, listener, timer and observer it took through
 * the scope is released).
 *
 *     export function notice(app: App, scope: Scope): HTMLElement {
 *       const element = host(html`<p class="notice" role="status"></p>`);
 *       mount(app, scope, element, ["notice"], ({ notice }) => notice?.text ?? "");
 *       return element;
 *     }
 */
import { render } from "lit-html";
import type { Scope } from "../ui/scope";
import { type App, type AppState, type Topic, state, watchState } from "./app";

/**
 * Render `template(state)` into `element` now and whenever one of `topics` changes, until `scope` goes.
 * Returns the render, for a change of the view's own (a filter typed, a button pressed).
 */
export function mount(
  app: App,
  scope: Scope,
  element: HTMLElement | SVGElement,
  topics: readonly Topic[],
  template: (state: AppState) => unknown,
): () => void {
  const draw = () => {
    if (!scope.disposed) render(template(state(app)), element);
  };
  watchState(app, scope, topics, draw);
  draw();
  return draw;
}
