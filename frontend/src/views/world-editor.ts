/**
 * The world editor: a form for the world and its regions beside a live drawing of it, loaded from the
 * library, a scenario or the selected run, saved to the library (PUT /api/worlds/{name}) or deleted
 * from it (DELETE /api/worlds/{name}, two presses). The server's 422s appear at the fields they concern.
 * The drawing is drawn on: drag to add a region, drag a region to move it, drag a corner to resize it,
 * click to set the start; the form follows, and Undo (or Ctrl+Z) takes back the last change. "Launch on
 * this world" saves it and starts an empty run on it (until paused, at a watching speed), selected on Live.
 */
import { attempt, deleteWorld, launchRun, notify, refreshWorlds } from "../app/actions";
import { type App, type AppState, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { ApiError, api, toApiError, unwrap } from "../api/client";
import type { Region, WorldSpec } from "../api/types";
import { gridWorld } from "../api/types";
import { runLabel } from "../lib/format";
import { formatList } from "../lib/parse";
import { WATCH_HZ } from "../lib/runs";
import { confirmButton } from "../ui/legacy-confirm";
import { h, options, replaceChildren } from "../ui/dom";
import { type FieldSpec, fieldTable } from "../ui/legacy-fields";
import { FormErrors, field } from "../ui/legacy-form";
import { type RegionFields, type RegionText, regionFields, regionText } from "./region-fields";
import { worldDrawing } from "./world-drawing";

const NEW_WORLD: WorldSpec = {
  width: 500,
  height: 500,
  step: 100,
  slip: 0,
  noise: 0,
  start: [0, 0],
  transient_reward: -0.01,
  max_steps: 100,
  regions: [{ name: "goal", kind: "terminal", rect: [400, 400, 500, 500], reward: 1 }],
};

const NEW_REGION: RegionText = { name: "", kind: "zone", rect: "0, 0, 100, 100", reward: "", colors: "" };

const UNDO_DEPTH = 50;

type WorldField = "name" | "start" | "width" | "height" | "step" | "max_steps" | "slip" | "noise" | "transient_reward";

/** The world's plain fields, once: the form, the filling, the reading and Undo all come from this list. */
const WORLD_FIELDS: readonly FieldSpec<WorldField>[] = [
  { key: "name", label: "Name", kind: "text", row: 0 },
  { key: "start", label: "Start", kind: "numbers", hint: "x, y or x0, y0, x1, y1", row: 0 },
  { key: "width", label: "Width", kind: "number", row: 1 },
  { key: "height", label: "Height", kind: "number", row: 1 },
  { key: "step", label: "Step", kind: "number", row: 1 },
  { key: "max_steps", label: "Max steps", kind: "number", row: 1 },
  { key: "slip", label: "Slip", kind: "number", hint: "chance of a sideways move", row: 2 },
  { key: "noise", label: "Noise", kind: "number", hint: "std of each move", row: 2 },
  { key: "transient_reward", label: "Reward per step", kind: "number", row: 2 },
];

/** Everything the form holds, as typed: what Undo restores. */
interface Snapshot {
  fields: string[];
  regions: RegionText[];
}

export function worldEditor(app: App, scope: Scope): HTMLElement {
  const errors = new FormErrors();
  const newKind = h(
    "select",
    { id: "new-region-kind" },
    options(["obstacle", "terminal", "zone", "indicator"], "obstacle"),
  );
  const undo = h("button", { type: "button", disabled: true, "aria-keyshortcuts": "Control+Z" }, "Undo");
  const history: Snapshot[] = [];
  const drawing = worldDrawing({
    newKind: () => newKind.value as Region["kind"],
    onEdit: (world, done) => {
      if (!done) {
        drawing.draw(world);
        return;
      }
      remember();
      fields.inputs.start.value = formatList(world.start ?? [0, 0]);
      setRegions((world.regions ?? []).map(regionText));
      redraw();
    },
  });

  const source = h("select", { id: "world-source" });
  /** The library world chosen in "Start from", if one is. */
  const libraryChoice = (): string | null =>
    source.value.startsWith("library:") ? source.value.slice("library:".length) : null;

  const load = h("button", { type: "button" }, "Load");
  // Deleting takes two presses, so a stray click cannot throw a world away.
  const remove = confirmButton({
    text: (armed) => (armed ? "Really delete?" : "Delete"),
    label: (armed) => {
      const world = libraryChoice();
      if (world === null) return "Delete a library world";
      return armed ? `Really delete world ${world} from the library?` : `Delete world ${world} from the library`;
    },
    onConfirm: () => {
      const world = libraryChoice();
      if (world === null) return;
      remove.button.disabled = true;
      void attempt(app, async () => {
        await deleteWorld(app, world);
        notify(app, `Deleted world '${world}' from the library.`);
      }).finally(renderRemove);
    },
  });
  const fields = fieldTable(WORLD_FIELDS, errors);
  const regionList = h("div", { class: "region-list" });

  const snapshot = (): Snapshot => ({
    fields: fields.texts(),
    regions: regions.map((r) => r.text()),
  });
  /** Keep the form as it is now, for Undo (before a change by drawing, adding or removing). */
  const remember = () => {
    history.push(snapshot());
    if (history.length > UNDO_DEPTH) history.shift();
    undo.disabled = false;
  };
  const takeBack = () => {
    const last = history.pop();
    undo.disabled = history.length === 0;
    if (!last) return;
    fields.setTexts(last.fields);
    setRegions(last.regions);
    redraw();
  };
  undo.addEventListener("click", takeBack);
  const addRegion = h("button", { type: "button" }, "Add region");
  const save = h("button", { type: "submit", class: "primary" }, "Save to library");
  const launch = h("button", { type: "button" }, "Launch on this world");
  let regions: RegionFields[] = [];

  const setRegions = (texts: RegionText[]) => {
    errors.unregister("regions");
    regions = texts.map((text, i) =>
      regionFields(text, `regions.${i}`, errors, redraw, () => {
        remember();
        setRegions(regions.filter((_, j) => j !== i).map((r) => r.text()));
        redraw();
        addRegion.focus();
      }),
    );
    replaceChildren(
      regionList,
      regions.map((r) => r.element),
    );
  };

  const fill = (world: WorldSpec, worldName: string) => {
    errors.clear();
    fields.fill({ ...world, name: worldName, start: world.start ?? [0, 0] });
    setRegions((world.regions ?? []).map(regionText));
    redraw();
  };

  const readFields = (): WorldSpec => fields.read() as WorldSpec;
  /** The world the form describes; throws InputError where a field cannot be read at all. */
  const read = (): WorldSpec => ({ ...readFields(), regions: regions.map((r) => r.read()) });

  // The drawing follows every keystroke; a field that does not read (yet) leaves its region out.
  function redraw(): void {
    const readable: Region[] = [];
    for (const region of regions) {
      try {
        readable.push(region.read());
      } catch {
        // half-typed JSON reward: the region is drawn once it reads
      }
    }
    drawing.draw({ ...readFields(), regions: readable });
  }

  const renderRemove = () => {
    const world = libraryChoice();
    remove.button.disabled = world === null;
    remove.button.title = world === null ? "Choose a library world under “Start from” first" : "";
    remove.refresh();
  };

  source.addEventListener("change", () => {
    remove.disarm();
    renderRemove();
  });

  const renderSources = () => {
    const chosen = source.value;
    const { worlds, scenarios, run } = state(app);
    replaceChildren(
      source,
      options(
        [
          ["new", "a new world"],
          ...(run ? [["run", `the selected run's world (${run.name ?? run.id.slice(0, 6)})`] as const] : []),
          ...worlds.map((w) => [`library:${w.name}`, `library: ${w.name}`] as const),
          ...scenarios.filter((s) => !s.error).map((s) => [`scenario:${s.name}`, `scenario: ${s.name}`] as const),
        ],
        chosen,
      ),
    );
    renderRemove();
  };

  const loadChosen = () =>
    attempt(app, async () => {
      const [kind, key = ""] = source.value.split(/:(.*)/s);
      if (kind === "library") {
        const record = await unwrap(api.GET("/api/worlds/{name}", { params: { path: { name: key } } }));
        fill(record.world, record.name);
      } else if (kind === "scenario") {
        const spec = await unwrap(api.GET("/api/scenarios/{name}", { params: { path: { name: key } } }));
        fill(gridWorld(spec.world) ?? NEW_WORLD, spec.world?.name ?? `${key}-world`);
      } else if (kind === "run" && state(app).run) {
        const run = state(app).run as NonNullable<AppState["run"]>;
        fill(gridWorld(run.spec.world) ?? NEW_WORLD, run.spec.world?.name ?? `${run.spec.name ?? "run"}-world`);
      } else {
        fill(NEW_WORLD, "my-world");
      }
    });
  load.addEventListener("click", () => void loadChosen());

  addRegion.addEventListener("click", () => {
    remember();
    const texts = regions.map((r) => r.text());
    setRegions([...texts, { ...NEW_REGION, name: `region${texts.length + 1}` }]);
    redraw();
    regions.at(-1)?.element.querySelector("input")?.focus();
  });

  /** Save the form's world to the library; its name, or null where the form or the server refused it. */
  const saveWorld = async (): Promise<string | null> => {
    errors.clear();
    const world = errors.readOrShow(read);
    if (world === null) return null;
    const worldName = world.name ?? "";
    save.disabled = launch.disabled = true;
    try {
      const { data, error, response } = await api.PUT("/api/worlds/{name}", {
        params: { path: { name: worldName } },
        body: world,
      });
      if (!response.ok || !data) throw toApiError(response.status, error);
      notify(app, `${response.status === 201 ? "Saved the new" : "Replaced the"} world '${data.name}' in the library.`);
      await refreshWorlds(app);
      source.value = `library:${data.name}`;
      renderRemove();
      return data.name;
    } catch (error) {
      if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
      else errors.showGeneral(error instanceof Error ? error.message : String(error));
      return null;
    } finally {
      save.disabled = launch.disabled = false;
    }
  };
  const onSubmit = (event: Event) => {
    event.preventDefault();
    void saveWorld();
  };
  // An empty run (no scenario: the default spec, no demons) on the saved world, watched at once.
  launch.addEventListener("click", async () => {
    const worldName = await saveWorld();
    if (worldName === null) return;
    await attempt(app, async () => {
      const template = { name: `empty-on-${worldName}`.slice(0, 64), world: worldName, protocol: { episodes: 0 } };
      const run = await launchRun(app, template, WATCH_HZ, true);
      notify(app, `Launched run ${runLabel(run)} on the world '${worldName}'.`);
      app.ui.update({ tab: "live" });
    });
  });

  watchState(app, scope, ["worlds", "scenarios", "run"], renderSources);
  renderSources();
  fill(NEW_WORLD, "my-world");

  const form = h(
    "form",
    { class: "world-form", novalidate: true, onsubmit: onSubmit, oninput: redraw, "aria-label": "World" },
    h("div", { class: "row load-row" }, field("Start from", source), load, remove.button),
    h("fieldset", {}, h("legend", {}, "World"), fields.rows()),
    h("h3", {}, "Regions"),
    errors.register("regions", null),
    regionList,
    h("div", { class: "actions" }, addRegion),
    errors.general,
    h("div", { class: "actions sticky-actions" }, save, launch),
  );

  const editor = h(
    "div",
    { class: "editor-grid" },
    form,
    h(
      "aside",
      { class: "drawing-column", "aria-label": "Drawing of the world" },
      h(
        "div",
        { class: "row tight drawing-tools" },
        field("Draw new regions as", newKind, { class: "inline-field" }),
        undo,
      ),
      h(
        "p",
        { class: "hint" },
        "Drag on empty ground to draw a region, drag a region to move it, drag a corner to resize it; click to set the start. Everything snaps to the step grid.",
      ),
      drawing.element,
    ),
  );
  // Ctrl+Z undoes a drawing change, except in a text field (which undoes its own typing).
  editor.addEventListener("keydown", (event) => {
    const typing = event.target instanceof HTMLInputElement || event.target instanceof HTMLTextAreaElement;
    if ((event.ctrlKey || event.metaKey) && event.key === "z" && !typing && !undo.disabled) {
      takeBack();
      event.preventDefault();
    }
  });
  return editor;
}
