/**
 * One region of the world editor: name, kind, rectangle, and the fields of its kind (a terminal's
 * reward, an indicator's colours). `read()` gives the Region the form describes.
 */
import type { Color, Region, RegionKind } from "../api/types";
import { InputError } from "../lib/input-error";
import { formatList, readNumber, readNumberList } from "../lib/parse";
import { h, options } from "../ui/dom";
import { type FormErrors, field, textInput } from "../ui/legacy-form";

const KINDS: readonly RegionKind[] = ["obstacle", "terminal", "zone", "indicator"];

/** A region as the form holds it: text, not yet parsed (so a half-typed region survives a re-index). */
export interface RegionText {
  name: string;
  kind: RegionKind;
  rect: string;
  reward: string;
  colors: string;
}

export interface RegionFields {
  element: HTMLFieldSetElement;
  read: () => Region;
  text: () => RegionText;
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

export function regionFields(
  region: RegionText,
  path: string,
  errors: FormErrors,
  onChange: () => void,
  onRemove: () => void,
): RegionFields {
  const name = textInput(region.name, { "data-field": "region-name" });
  const kind = h("select", { "data-field": "region-kind" }, options(KINDS, region.kind));
  const rect = textInput(region.rect, { "data-field": "region-rect" });
  const reward = textInput(region.reward, { "data-field": "region-reward" });
  const colors = h("textarea", { rows: 3, spellcheck: "false", "data-field": "region-colors" });
  colors.value = region.colors;
  const legend = h("legend", {}, region.name || "new region");

  const rewardField = field("Reward", reward, {
    path: `${path}.reward`,
    errors,
    hint: 'or per colour: {"indicator": …, "values": {…}}',
    class: "wide",
  });
  const colorsField = field("Colours", colors, {
    path: `${path}.colors`,
    errors,
    hint: "one a line: name, value, probability (e.g. yellow, 1, 0.5)",
  });
  const showKindFields = () => {
    rewardField.hidden = kind.value !== "terminal";
    colorsField.hidden = kind.value !== "indicator";
  };
  showKindFields();

  // Problems of the region as a whole ("terminal region 'a' needs a reward" names a field and goes there).
  const regionError = errors.register(path, null);
  const remove = h("button", { type: "button", class: "danger small", onclick: onRemove }, "Remove");
  const setNames = () => {
    legend.textContent = name.value || "new region";
    remove.setAttribute("aria-label", `Remove region ${name.value || "new region"}`);
  };
  setNames();

  const element = h(
    "fieldset",
    { class: "region", oninput: onChange, onchange: onChange },
    legend,
    h(
      "div",
      { class: "row" },
      field("Name", name, { path: `${path}.name`, errors }),
      field("Kind", kind, { path: `${path}.kind`, errors }),
      field("Rectangle", rect, { path: `${path}.rect`, errors, hint: "x0, y0, x1, y1", class: "wide" }),
      rewardField,
      h("div", { class: "remove" }, remove),
    ),
    colorsField,
    regionError,
  );
  kind.addEventListener("change", showKindFields);
  name.addEventListener("input", setNames);

  const read = (): Region => {
    const value: Region = { name: name.value.trim(), kind: kind.value as RegionKind, rect: readNumberList(rect.value) };
    if (value.kind === "terminal") value.reward = readReward(reward.value, `${path}.reward`);
    if (value.kind === "indicator") value.colors = readColors(colors.value);
    return value;
  };
  const text = (): RegionText => ({
    name: name.value,
    kind: kind.value as RegionKind,
    rect: rect.value,
    reward: reward.value,
    colors: colors.value,
  });
  return { element, read, text };
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
