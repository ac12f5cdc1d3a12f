/** What the world editor (views/world-editor.ts) holds, and what it asks of the server: load, save, launch. */
import type { Ref } from "lit-html/directives/ref.js";
import { attempt, launchRun, notify, refreshWorlds } from "../app/actions";
import { type App, state } from "../app/app";
import { ApiError, api, errorMessage, toApiError, unwrap } from "../api/client";
import type { WorldSpec } from "../api/types";
import { gridWorld } from "../api/types";
import { runLabel } from "../lib/format";
import { WATCH_HZ } from "../lib/runs";
import type { Confirm } from "../ui/confirm";
import type { FieldSpec, FieldTable } from "../ui/fields";
import { type FormErrors, setValue, valueOf } from "../ui/form";
import { type RegionText, readRegion } from "./region-fields";
import type { WorldDrawing } from "./world-drawing";

/** The world a new form starts from. */
export const NEW_WORLD: WorldSpec = {
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

export type WorldField =
  "name" | "start" | "width" | "height" | "step" | "max_steps" | "slip" | "noise" | "transient_reward";

/** The world's plain fields, once: the form, the filling, the reading and Undo all come from this list. */
export const WORLD_FIELDS: readonly FieldSpec<WorldField>[] = [
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
export interface Snapshot {
  fields: string[];
  regions: RegionText[];
}

export interface WorldForm {
  app: App;
  element: HTMLElement;
  errors: FormErrors;
  fields: FieldTable<WorldField>;
  /** the regions as typed */
  regions: RegionText[];
  /** Undo's steps back, the newest last */
  history: Snapshot[];
  source: Ref<HTMLSelectElement>;
  newKind: Ref<HTMLSelectElement>;
  /** saving or launching: the buttons wait */
  busy: boolean;
  remove: Confirm;
  drawing: WorldDrawing;
  /** draw the form and the drawing again */
  changed: () => void;
  /** show `world`, named `name` */
  fill: (world: WorldSpec, name: string) => void;
}

/** The world the form describes; throws InputError where a field cannot be read at all. */
function read(form: WorldForm): WorldSpec {
  return {
    ...(form.fields.read() as WorldSpec),
    regions: form.regions.map((region, i) => readRegion(region, `regions.${i}`)),
  };
}

/** Load what "Start from" names into the form. */
export async function loadChosen(form: WorldForm): Promise<void> {
  const { app } = form;
  const fallback = NEW_WORLD;
  await attempt(app, async () => {
    const [kind, key = ""] = valueOf(form.source).split(/:(.*)/s);
    const run = state(app).run;
    if (kind === "library") {
      const record = await unwrap(api.GET("/api/worlds/{name}", { params: { path: { name: key } } }));
      form.fill(record.world, record.name);
    } else if (kind === "scenario") {
      const spec = await unwrap(api.GET("/api/scenarios/{name}", { params: { path: { name: key } } }));
      form.fill(gridWorld(spec.world) ?? fallback, spec.world?.name ?? `${key}-world`);
    } else if (kind === "run" && run) {
      form.fill(gridWorld(run.spec.world) ?? fallback, run.spec.world?.name ?? `${run.spec.name ?? "run"}-world`);
    } else {
      form.fill(fallback, "my-world");
    }
  });
}

/** Save the form's world to the library; its name, or null where the form or the server refused it. */
export async function saveWorld(form: WorldForm): Promise<string | null> {
  const { app, errors } = form;
  errors.clear();
  const world = errors.readOrShow(() => read(form));
  if (world === null) return null;
  const name = world.name ?? "";
  form.busy = true;
  form.changed();
  try {
    const { data, error, response } = await api.PUT("/api/worlds/{name}", { params: { path: { name } }, body: world });
    if (!response.ok || !data) throw toApiError(response.status, error);
    notify(app, `${response.status === 201 ? "Saved the new" : "Replaced the"} world '${data.name}' in the library.`);
    await refreshWorlds(app);
    setValue(form.source, `library:${data.name}`);
    return data.name;
  } catch (error) {
    if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
    else errors.showGeneral(errorMessage(error));
    return null;
  } finally {
    form.busy = false;
    form.changed();
  }
}

/** An empty run (no scenario: the default spec, no demons) on the saved world, watched at once. */
export async function launchOnWorld(form: WorldForm): Promise<void> {
  const { app } = form;
  const name = await saveWorld(form);
  if (name === null) return;
  await attempt(app, async () => {
    const template = { name: `empty-on-${name}`.slice(0, 64), world: name, protocol: { episodes: 0 } };
    const run = await launchRun(app, template, WATCH_HZ, true);
    notify(app, `Launched run ${runLabel(run)} on the world '${name}'.`);
    app.ui.update({ tab: "live" });
  });
}
