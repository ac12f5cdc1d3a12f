/**
 * The world editor: a form for the world and its regions beside a live drawing of it, loaded from the
 * library, a scenario or the selected run, saved to the library (PUT /api/worlds/{name}) or deleted
 * from it (DELETE /api/worlds/{name}, two presses). The server's 422s appear at the fields they concern.
 * The drawing is drawn on: drag to add a region, drag a region to move it, drag a corner to resize it,
 * click to set the start; the form follows, and Undo (or Ctrl+Z) takes back the last change. "Launch on
 * this world" saves it and starts an empty run on it (until paused, at a watching speed), selected on Live.
 */
import { html } from "lit-html";
import { createRef } from "lit-html/directives/ref.js";
import { attempt, deleteWorld, notify } from "../app/actions";
import type { App, AppState } from "../app/app";
import { mount } from "../app/view";
import type { Region, WorldSpec } from "../api/types";
import { formatList } from "../lib/parse";
import { Confirm, confirmButton } from "../ui/confirm";
import { fieldTable } from "../ui/fields";
import { FormErrors, errorSlot, generalError, selectField, valueOf } from "../ui/form";
import { choices, host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { type RegionText, readRegion, regionFields, regionText } from "./region-fields";
import { worldDrawing } from "./world-drawing";
import { NEW_WORLD, WORLD_FIELDS, type WorldForm, launchOnWorld, loadChosen, saveWorld } from "./world-form";

const NEW_REGION: RegionText = { name: "", kind: "zone", rect: "0, 0, 100, 100", reward: "", colors: "" };
const UNDO_DEPTH = 50;

export function worldEditor(app: App, scope: Scope): HTMLElement {
  const element = host(html`<div class="editor-grid"></div>`);
  const redraw = () => draw();
  const errors = new FormErrors(element, redraw);
  const form: WorldForm = {
    app,
    element,
    errors,
    fields: fieldTable(WORLD_FIELDS, errors),
    regions: [],
    history: [],
    source: createRef(),
    newKind: createRef(),
    busy: false,
    remove: new Confirm(scope, redraw),
    drawing: worldDrawing({
      newKind: () => (valueOf(form.newKind) || "obstacle") as Region["kind"],
      onEdit: (world, done) => (done ? edited(form, world) : form.drawing.draw(world)),
    }),
    changed: () => {
      draw();
      showWorld(form);
    },
    fill: (world, name) => fill(form, world, name),
  };
  const draw = mount(app, scope, element, ["worlds", "scenarios", "run"], (now) => editorTemplate(form, now));
  form.fill(NEW_WORLD, "my-world");
  // Ctrl+Z undoes a drawing change, except in a text field (which undoes its own typing).
  scope.listen<KeyboardEvent>(element, "keydown", (event) => {
    const typing = event.target instanceof HTMLInputElement || event.target instanceof HTMLTextAreaElement;
    if ((event.ctrlKey || event.metaKey) && event.key === "z" && !typing && form.history.length > 0) {
      takeBack(form);
      event.preventDefault();
    }
  });
  return element;
}

function editorTemplate(form: WorldForm, now: AppState) {
  const { errors } = form;
  const changed = () => form.changed();
  return html`<form
      class="world-form"
      novalidate
      aria-label="World"
      @submit=${(event: Event) => {
        event.preventDefault();
        void saveWorld(form);
      }}
      @input=${(event: Event) => {
        errors.onInput(event);
        showWorld(form);
      }}
      @change=${errors.onInput}
    >
      ${sourceRow(form, now)}
      <fieldset>
        <legend>World</legend>
        ${form.fields.rows()}
      </fieldset>
      <h3>Regions</h3>
      ${errorSlot(errors, "regions")}
      <div class="region-list">
        ${form.regions.map((region, i) =>
          regionFields(region, i, errors, changed, () => {
            remember(form);
            form.regions = form.regions.filter((_, j) => j !== i);
            errors.forget("regions");
            changed();
            form.element.querySelector<HTMLElement>("#world-add-region")?.focus();
          }),
        )}
      </div>
      <div class="actions">
        <button type="button" id="world-add-region" @click=${() => addRegion(form)}>Add region</button>
      </div>
      ${generalError(errors)}
      <div class="actions sticky-actions">
        <button type="submit" class="primary needs-change" ?disabled=${form.busy}>Save to library</button>
        <button type="button" class="needs-change" ?disabled=${form.busy} @click=${() => void launchOnWorld(form)}>
          Launch on this world
        </button>
      </div>
    </form>
    <aside class="drawing-column" aria-label="Drawing of the world">
      <div class="row tight drawing-tools">
        ${selectField(
          { label: "Draw new regions as", id: "new-region-kind", class: "inline-field" },
          { ref: form.newKind },
          choices(["obstacle", "terminal", "zone", "indicator"], "obstacle"),
        )}
        <button
          type="button"
          aria-keyshortcuts="Control+Z"
          ?disabled=${form.history.length === 0}
          @click=${() => takeBack(form)}
        >
          Undo
        </button>
      </div>
      <p class="hint">
        Drag on empty ground to draw a region, drag a region to move it, drag a corner to resize it; click to set the
        start. Everything snaps to the step grid.
      </p>
      ${form.drawing.element}
    </aside>`;
}

/** "Start from" (a new world, the selected run's, a library world, a scenario's), Load and Delete. */
function sourceRow(form: WorldForm, { worlds, scenarios, run }: AppState) {
  const chosen = valueOf(form.source);
  const world = chosen.startsWith("library:") ? chosen.slice("library:".length) : null;
  const items: (readonly [string, string])[] = [
    ["new", "a new world"],
    ...(run ? [["run", `the selected run's world (${run.name ?? run.id.slice(0, 6)})`] as const] : []),
    ...worlds.map((w) => [`library:${w.name}`, `library: ${w.name}`] as const),
    ...scenarios.filter((s) => !s.error).map((s) => [`scenario:${s.name}`, `scenario: ${s.name}`] as const),
  ];
  // Deleting takes two presses, so a stray click cannot throw a world away.
  const remove = confirmButton(form.remove, {
    class: "danger needs-teacher",
    text: (armed) => (armed ? "Really delete?" : "Delete"),
    label: (armed) =>
      world === null
        ? "Delete a library world"
        : armed
          ? `Really delete world ${world} from the library?`
          : `Delete world ${world} from the library`,
    disabled: world === null || form.busy,
    title: world === null ? "Choose a library world under “Start from” first" : undefined,
    onConfirm: () => {
      if (world === null) return;
      void attempt(form.app, async () => {
        await deleteWorld(form.app, world);
        notify(form.app, `Deleted world '${world}' from the library.`);
      });
    },
  });
  return html`<div class="row load-row">
    ${selectField(
      { label: "Start from", id: "world-source" },
      {
        ref: form.source,
        onChange: () => {
          form.remove.disarm();
          form.changed();
        },
      },
      choices(items, chosen || "new"),
    )}
    <button type="button" @click=${() => void loadChosen(form)}>Load</button>
    ${remove}
  </div>`;
}

/** Keep the form as it is now, for Undo (before a change by drawing, adding or removing). */
function remember(form: WorldForm): void {
  form.history.push({ fields: form.fields.texts(), regions: form.regions.map((r) => ({ ...r })) });
  if (form.history.length > UNDO_DEPTH) form.history.shift();
}

function takeBack(form: WorldForm): void {
  const last = form.history.pop();
  if (!last) return;
  form.fields.setTexts(last.fields);
  form.regions = last.regions;
  form.errors.forget("regions");
  form.changed();
}

function addRegion(form: WorldForm): void {
  remember(form);
  form.regions = [...form.regions, { ...NEW_REGION, name: `region${form.regions.length + 1}` }];
  form.changed();
  const fieldsets = form.element.querySelectorAll<HTMLElement>("fieldset.region");
  fieldsets[fieldsets.length - 1]?.querySelector("input")?.focus();
}

/** A drag on the drawing has ended: the form follows it, and Undo can take it back. */
function edited(form: WorldForm, world: WorldSpec): void {
  remember(form);
  const start = form.fields.input("start");
  if (start) start.value = formatList(world.start ?? [0, 0]);
  form.regions = (world.regions ?? []).map(regionText);
  form.errors.forget("regions");
  form.changed();
}

function fill(form: WorldForm, world: WorldSpec, name: string): void {
  form.errors.clear();
  form.fields.fill({ ...world, name, start: world.start ?? [0, 0] });
  form.regions = (world.regions ?? []).map(regionText);
  form.changed();
}

/** The drawing follows every keystroke; a region that does not read (yet) is left out. */
function showWorld(form: WorldForm): void {
  const readable: Region[] = [];
  form.regions.forEach((region, i) => {
    try {
      readable.push(readRegion(region, `regions.${i}`));
    } catch {
      // half-typed JSON reward: the region is drawn once it reads
    }
  });
  form.drawing.draw({ ...(form.fields.read() as WorldSpec), regions: readable });
}
