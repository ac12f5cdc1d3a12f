import { describe, expect, it } from "vitest";
import type { History } from "../src/api/types";
import { latestErrors } from "../src/lib/state-errors";

const history = (demon: string, rmsve: (number | null)[] | null, rmspbe: (number | null)[] | null): History =>
  ({ demon, every: 1, capacity: 16, step: [1, 2], prediction: [0, 0], rmsve, rmspbe }) as unknown as History;

describe("latestErrors", () => {
  it("takes each demon's RMSVE and RMSPBE at its history's last row", () => {
    const errors = latestErrors([history("td", [0.5, 0.25], [0.1, 0.05]), history("gq", [null, null], [null, null])]);
    expect(errors?.get("td")).toEqual({ rmsve: 0.25, rmspbe: 0.05 });
    expect(errors?.get("gq")).toEqual({ rmsve: null, rmspbe: null }); // a demon without a truth: a blank cell
  });

  it("is null, not zeros, for a run whose world has no discrete states (its history has none)", () => {
    expect(latestErrors([history("a", null, null), history("b", null, null)])).toBeNull();
    expect(latestErrors([])).toBeNull();
  });
});
