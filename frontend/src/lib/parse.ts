/**
 * Form text to request values. Numbers are passed on as typed, not checked here: the server validates
 * every field and its 422 is shown at the field, so the rules live in one place (the pydantic models).
 * Text that is no number becomes NaN, which JSON sends as null and the server refuses by name.
 */

/** The number in a field; NaN when it is empty or no number. */
export function readNumber(text: string): number {
  return text.trim() === "" ? Number.NaN : Number(text.trim());
}

/** The number in an optional field; undefined (left out of the request: the default) when empty. */
export function readOptionalNumber(text: string): number | undefined {
  return text.trim() === "" ? undefined : Number(text.trim());
}

/** A list of numbers typed with commas or spaces ("400, 400, 500, 500"). */
export function readNumberList(text: string): number[] {
  return text
    .split(/[\s,]+/)
    .filter((part) => part !== "")
    .map((part) => Number(part));
}

export function formatList(values: readonly number[] | null | undefined): string {
  return (values ?? []).join(", ");
}
