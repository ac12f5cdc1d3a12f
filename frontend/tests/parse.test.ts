import { describe, expect, it } from "vitest";
import { formatList, readNumber, readNumberList, readOptionalNumber } from "../src/lib/parse";

describe("reading form fields", () => {
  it("reads numbers, NaN for what is none", () => {
    expect(readNumber(" 2.5 ")).toBe(2.5);
    expect(readNumber("")).toBeNaN();
    expect(readNumber("abc")).toBeNaN();
  });
  it("leaves an empty optional field out", () => {
    expect(readOptionalNumber("")).toBeUndefined();
    expect(readOptionalNumber("0.9")).toBe(0.9);
  });
  it("reads lists written with commas or spaces, and writes them back", () => {
    expect(readNumberList("400, 400,500 500")).toEqual([400, 400, 500, 500]);
    expect(readNumberList("1, x")).toEqual([1, Number.NaN]);
    expect(formatList([400, 200, 500, 300])).toBe("400, 200, 500, 300");
    expect(formatList(undefined)).toBe("");
  });
});
