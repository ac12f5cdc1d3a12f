import { describe, expect, it } from "vitest";
import { ApiError, errorMessage, toApiError } from "../src/api/client";
import { streamUrl } from "../src/api/stream";

describe("toApiError", () => {
  it("keeps a 422's located problems", () => {
    const problems = [
      { loc: ["body", "lambda"], msg: "Input should be less than or equal to 1", type: "less_than_equal" },
    ];
    const error = toApiError(422, { detail: problems });
    expect(error).toBeInstanceOf(ApiError);
    expect(error.status).toBe(422);
    expect(error.problems).toEqual(problems);
    expect(error.message).toBe("Input should be less than or equal to 1");
  });

  it("takes the message of a 404 or 409", () => {
    const error = toApiError(409, { detail: "run 'x' is running" });
    expect(error.message).toBe("run 'x' is running");
    expect(error.problems).toEqual([]);
  });

  it("says the status when the body says nothing", () => {
    expect(toApiError(502, "Bad gateway").message).toBe("the server answered 502");
    expect(errorMessage(new Error("offline"))).toBe("offline");
    expect(errorMessage("odd")).toBe("odd");
  });
});

describe("streamUrl", () => {
  it("follows the page's scheme and host", () => {
    expect(streamUrl("abc", { protocol: "http:", host: "127.0.0.1:8000" })).toBe(
      "ws://127.0.0.1:8000/api/runs/abc/stream",
    );
    expect(streamUrl("a b", { protocol: "https:", host: "lab.example" })).toBe(
      "wss://lab.example/api/runs/a%20b/stream",
    );
  });
});
