/**
 * A demon's features: the run's own, or stripes / tiles / grid / constant with their sizes.
 * (A `condition` on another demon's prediction is written in a scenario file; the form keeps one it loads.)
 */
import type { FeatureSpec } from "../api/types";
import { readNumber } from "../lib/parse";
import { h, options } from "../ui/dom";
import { type FormErrors, field, numberInput } from "../ui/legacy-form";

const RUN_FEATURES = "run";
type Kind = FeatureSpec["kind"];
const KINDS: readonly (readonly [string, string])[] = [
  [RUN_FEATURES, "the run's features"],
  ["stripes", "stripes (the thesis)"],
  ["tiles", "tile coding"],
  ["grid", "grid (tabular)"],
  ["constant", "constant (a bias only)"],
];

export interface FeaturesFields {
  element: HTMLElement;
  read: () => FeatureSpec | null;
  set: (features: FeatureSpec | null | undefined) => void;
}

export function featuresFields(errors: FormErrors): FeaturesFields {
  const kind = h("select", { "data-field": "features-kind" }, options(KINDS, RUN_FEATURES));
  const parts = numberInput(5);
  const tilings = numberInput(8);
  const tiles = numberInput(8);
  const sizeFields = {
    parts: field("Parts", parts, { path: "features.parts", errors }),
    tilings: field("Tilings", tilings, { path: "features.tilings", errors }),
    tiles: field("Tiles", tiles, { path: "features.tiles", errors }),
  };
  const uses: Record<string, (keyof typeof sizeFields)[]> = {
    stripes: ["parts"],
    tiles: ["tilings", "tiles"],
    grid: ["tiles"],
  };
  let condition: FeatureSpec["condition"] = null;
  const show = () => {
    const used = uses[kind.value] ?? [];
    for (const [name, element] of Object.entries(sizeFields))
      element.hidden = !used.includes(name as keyof typeof sizeFields);
  };
  kind.addEventListener("change", show);
  show();

  const set = (features: FeatureSpec | null | undefined) => {
    kind.value = features?.kind ?? RUN_FEATURES;
    parts.value = String(features?.parts ?? 5);
    tilings.value = String(features?.tilings ?? 8);
    tiles.value = String(features?.tiles ?? 8);
    condition = features?.condition ?? null;
    show();
  };

  const read = (): FeatureSpec | null => {
    if (kind.value === RUN_FEATURES) return null;
    const spec = { kind: kind.value as Kind } as FeatureSpec;
    for (const name of uses[kind.value] ?? []) spec[name] = readNumber({ parts, tilings, tiles }[name].value);
    if (condition) spec.condition = condition;
    return spec;
  };

  const element = h(
    "div",
    { class: "row" },
    field("Features", kind, { path: "features.kind", errors, term: "features" }),
    ...Object.values(sizeFields),
    errors.register("features", null),
  );
  return { element, read, set };
}
