/**
 * One region of the world editor: name, kind, rectangle, and the fields of its kind (a terminal's
 * reward, an indicator's colours), drawn from the region's text as the form holds it; `readRegion` gives
 * the Region that text describes.
 */
import { html } from "lit-html";
import type { Color, Region, RegionKind } from "../api/types";
import { InputError } from "../lib/input-error";
import { formatList, readNumber, readNumberList } from "../lib/parse";
import { type FormErrors, errorSlot, field, selectField, textArea, textField } from "../ui/form";
import { choices } from "../ui/html";

const KINDS: readonly RegionKind[] = ["obstacle", "terminal", "zone", "indicator"];

/** A region as the form holds it: text, not yet parsed (so a half-typed region survives a re-index). */
export interface RegionText {
  name: string;
  kind: RegionKind;
  rect: string;
  reward: string;
  colors: string;
}

export function regionText(region: Region): RegionText {
  return {
    name: region.name,
    kind: region.kind,
    rect: formatList(region.rect),
    reward: rewardText(region.reward),
    colors: colorsText(region.colors),
  };
}

/** The Region a region's text describes; throws InputError where a field cannot be read at all. */
export function readRegion(region: RegionText, path: string): Region {
  const value: Region = { name: region.name.trim(), kind: region.kind, rect: readNumberList(region.rect) };
  if (value.kind === "terminal") value.reward = readReward(region.reward, `${path}.reward`);
  if (value.kind === "indicator") value.colors = readColors(region.colors);
  return value;
}

/**
 * The fields of region `index` (its 422s under `regions.INDEX`): what is typed goes into `region` at once
 * and `changed` is told; `remove` takes the region out.
 */
export function regionFields(
  region: RegionText,
  index: number,
  errors: FormErrors,
  changed: () => void,
  remove: () => void,
) {
  const path = `regions.${index}`;
  const set = (key: Exclude<keyof RegionText, "kind">) => (event: Event) => {
    region[key] = (event.target as HTMLInputElement).value;
    changed();
  };
  const name = region.name || "new region";
  return html`<fieldset class="region">
    <legend>${name}</legend>
    <div class="row">
      ${textField(
        { label: "Name", path: `${path}.name`, errors },
        { field: "region-name", current: region.name, onInput: set("name") },
      )}
      ${selectField(
        { label: "Kind", path: `${path}.kind`, errors },
        {
          field: "region-kind",
          current: region.kind,
          onChange: (event) => {
            region.kind = (event.target as HTMLSelectElement).value as RegionKind;
            changed();
          },
        },
        choices(KINDS, region.kind),
      )}
      ${textField(
        { label: "Rectangle", path: `${path}.rect`, errors, hint: "x0, y0, x1, y1", class: "wide" },
        { field: "region-rect", current: region.rect, onInput: set("rect") },
      )}
      ${textField(
        {
          label: "Reward",
          path: `${path}.reward`,
          errors,
          hint: 'or per colour: {"indicator": …, "values": {…}}',
          class: "wide",
          hidden: region.kind !== "terminal",
        },
        { field: "region-reward", current: region.reward, onInput: set("reward") },
      )}
      <div class="remove">
        <button type="button" class="danger small" aria-label="Remove region ${name}" @click=${remove}>Remove</button>
      </div>
    </div>
    ${field(
      {
        label: "Colours",
        path: `${path}.colors`,
        errors,
        hint: "one a line: name, value, probability (e.g. yellow, 1, 0.5)",
        hidden: region.kind !== "indicator",
      },
      (c) => textArea(c, { field: "region-colors", current: region.colors, onInput: set("colors") }, 3),
    )}
    ${errorSlot(errors, path)}
  </fieldset>`;
}

function rewardText(reward: Region["reward"]): string {
  if (reward === null || reward === undefined) return "";
  return typeof reward === "number" ? String(reward) : JSON.stringify(reward);
}

function readReward(text: string, path: string): Region["reward"] {
  const trimmed = text.trim();
  if (trimmed === "" || !trimmed.startsWith("{")) return readNumber(trimmed);
  try {
    return JSON.parse(trimmed) as Region["reward"];
  } catch (error) {
    throw new InputError(path, `not JSON: ${(error as Error).message}`);
  }
}

function colorsText(colors: Color[] | null | undefined): string {
  return (colors ?? []).map((c) => `${c.name}, ${c.value}, ${c.probability}`).join("\n");
}

function readColors(text: string): Color[] {
  return text
    .split("\n")
    .map((line) => line.trim())
    .filter((line) => line !== "")
    .map((line) => {
      const [name = "", value = "", probability = ""] = line.split(/\s*,\s*|\s+/);
      return { name, value: readNumber(value), probability: readNumber(probability) };
    });
}
