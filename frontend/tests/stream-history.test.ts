import { describe, expect, it } from "vitest";
import type { StreamHistory } from "../src/api/types";
import { demonColumns, pickNames, sensorColumns, stripError } from "../src/lib/stream-history";

const history: StreamHistory = {
  records: [10, 11, 12, 14],
  sensors: { light: [0.1, 0.2, 0.3, 0.4] },
  predictions: { a: [1, 2, null, 4], b: [0, 0, 0, 0] },
  returns: { a: [1.5, 1, 3, null], b: null },
};

describe("the strip chart's data", () => {
  it("puts each prediction beside the realised return, gaps where it is unknown", () => {
    expect(sensorColumns(history, "light")).toEqual([
      [10, 11, 12, 14],
      [0.1, 0.2, 0.3, 0.4],
    ]);
    expect(demonColumns(history, "a")).toEqual([
      [10, 11, 12, 14],
      [1, 2, null, 4],
      [1.5, 1, 3, null],
    ]);
    // A demon whose question reads other demons has no realised return: an all-gap column, not a crash.
    expect(demonColumns(history, "b")[2]).toEqual([null, null, null, null]);
    expect(sensorColumns(history, "heat")[1]).toEqual([null, null, null, null]);
  });

  it("measures the error only where both the prediction and the return are known", () => {
    // rows 0 and 1: |1 - 1.5| and |2 - 1|; row 2 has no prediction, row 3 no return
    expect(stripError(history, "a")).toEqual({ count: 2, meanAbsolute: 0.75 });
    const none = stripError(history, "b");
    expect(none.count).toBe(0);
    expect(none.meanAbsolute).toBeNaN();
  });

  it("keeps the ticked names still offered, else the first ones, never more than the cap", () => {
    expect(pickNames(["x", "y", "z"], ["z", "gone"], 2, 8)).toEqual(["z"]);
    expect(pickNames(["x", "y", "z"], ["gone"], 2, 8)).toEqual(["x", "y"]);
    expect(pickNames(["x", "y", "z"], ["x", "y", "z"], 2, 2)).toEqual(["x", "y"]);
  });
});
