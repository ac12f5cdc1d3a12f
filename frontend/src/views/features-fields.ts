/**
 * A demon's features: the run's own, or stripes / tiles / grid / constant with their sizes.
 * (A `condition` on another demon's prediction is written in a scenario file; the form keeps one it loads.)
 */
import { html } from "lit-html";
import type { FeatureSpec } from "../api/types";
import { readNumber } from "../lib/parse";
import { type FormErrors, bound, errorSlot, numberField, selectField } from "../ui/form";
import { choices } from "../ui/html";

const RUN_FEATURES = "run";
type Size = "parts" | "tilings" | "tiles";
const KINDS: readonly (readonly [string, string])[] = [
  [RUN_FEATURES, "the run's features"],
  ["stripes", "stripes (the thesis)"],
  ["tiles", "tile coding"],
  ["grid", "grid (tabular)"],
  ["constant", "constant (a bias only)"],
];
const USES: Record<string, Size[]> = { stripes: ["parts"], tiles: ["tilings", "tiles"], grid: ["tiles"] };
const LABELS: Record<Size, string> = { parts: "Parts", tilings: "Tilings", tiles: "Tiles" };

/** Features as the form holds them (with a condition loaded from a demon, kept as it is). */
export interface FeaturesText extends Record<Size | "kind", string> {
  condition?: FeatureSpec["condition"];
}

export function featuresText(features: FeatureSpec | null | undefined): FeaturesText {
  return {
    kind: features?.kind ?? RUN_FEATURES,
    parts: String(features?.parts ?? 5),
    tilings: String(features?.tilings ?? 8),
    tiles: String(features?.tiles ?? 8),
    condition: features?.condition ?? null,
  };
}

export function readFeatures(text: FeaturesText): FeatureSpec | null {
  if (text.kind === RUN_FEATURES) return null;
  const spec = { kind: text.kind as FeatureSpec["kind"] } as FeatureSpec;
  for (const size of USES[text.kind] ?? []) spec[size] = readNumber(text[size]);
  if (text.condition) spec.condition = text.condition;
  return spec;
}

export function featuresFields(text: FeaturesText, errors: FormErrors, redraw: () => void) {
  const used = USES[text.kind] ?? [];
  return html`<div class="row">
    ${selectField(
      { label: "Features", path: "features.kind", errors, term: "features" },
      { field: "features-kind", ...bound(text, "kind", redraw) },
      choices(KINDS, text.kind),
    )}
    ${(["parts", "tilings", "tiles"] as const).map((size) =>
      numberField(
        { label: LABELS[size], path: `features.${size}`, errors, hidden: !used.includes(size) },
        bound(text, size),
      ),
    )}
    ${errorSlot(errors, "features")}
  </div>`;
}
