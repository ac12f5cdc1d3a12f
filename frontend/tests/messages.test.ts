import { describe, expect, it } from "vitest";
import { humanMessage } from "../src/lib/messages";

// Problems as the server sends them (pydantic 2: type, msg, ctx).
describe("humanMessage", () => {
  it("says what a name may hold instead of the regular expression", () => {
    const problem = {
      type: "string_pattern_mismatch",
      msg: "String should match pattern '^[A-Za-z_][A-Za-z0-9_.-]*$'",
      ctx: { pattern: "^[A-Za-z_][A-Za-z0-9_.-]*$" },
    };
    expect(humanMessage(problem)).toBe("Use letters, digits, _ . or - (no spaces), starting with a letter or _.");
  });

  it("counts items and limits in words", () => {
    const short = {
      type: "too_short",
      msg: "List should have at least 4 items after validation, not 3",
      ctx: { field_type: "List", min_length: 4, actual_length: 3 },
    };
    expect(humanMessage(short)).toBe("Needs at least 4 items.");
    expect(
      humanMessage({ type: "less_than_equal", msg: "Input should be less than or equal to 1", ctx: { le: 1 } }),
    ).toBe("Must be 1 or less.");
    expect(humanMessage({ type: "greater_than", msg: "Input should be greater than 0", ctx: { gt: 0 } })).toBe(
      "Must be more than 0.",
    );
    expect(humanMessage({ type: "less_than_equal", msg: "…", ctx: { le: 10000 } })).toBe("Must be 10,000 or less.");
  });

  it("keeps the project's own messages, without pydantic's prefix", () => {
    expect(humanMessage({ type: "value_error", msg: "Value error, rect must be ordered: x0 < x1" })).toBe(
      "rect must be ordered: x0 < x1",
    );
    expect(humanMessage({ type: "some_new_kind", msg: "Something odd" })).toBe("Something odd");
  });

  it("lists the choices of a literal without quotes", () => {
    const problem = { type: "literal_error", msg: "Input should be 'gq' or 'gtd'", ctx: { expected: "'gq' or 'gtd'" } };
    expect(humanMessage(problem)).toBe("Choose one of: gq or gtd.");
  });
});

describe("humanMessage without ctx", () => {
  it("reads the limit from pydantic's message", () => {
    const ge = { type: "greater_than_equal", msg: "Input should be greater than or equal to 1" };
    expect(humanMessage(ge)).toBe("Must be 1 or more.");
    expect(humanMessage({ type: "less_than_equal", msg: "Input should be less than or equal to 0.5" })).toBe(
      "Must be 0.5 or less.",
    );
    const short = { type: "too_short", msg: "List should have at least 4 items after validation, not 3" };
    expect(humanMessage(short)).toBe("Needs at least 4 items.");
    expect(humanMessage({ type: "literal_error", msg: "Input should be 'a' or 'b'" })).toBe(
      "Input should be 'a' or 'b'",
    );
  });
});
