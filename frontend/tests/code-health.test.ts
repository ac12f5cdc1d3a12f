// The dashboard's sources keep short functions and no import circles (issue 29), as tests/test_code_health.py
// holds the Python package to its bounds: `node scripts/code-health.mjs` prints the figures.
import { mkdtempSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { describe, expect, it } from "vitest";
import { MAX_FUNCTION_LINES, functionLengths, importCycles, measure } from "../scripts/code-health.mjs";

// frontend/src measured once (parsing every file takes a second or two).
const figures = measure();

describe("the dashboard's code health", () => {
  it(`has no function over ${MAX_FUNCTION_LINES} lines in frontend/src`, () => {
    const long = figures.functions.filter((f) => f.lines > MAX_FUNCTION_LINES);
    expect(long.map((f) => `${f.file}:${f.line} ${f.name}: ${f.lines} lines`)).toEqual([]);
  });

  it("has no import circle in frontend/src", () => {
    expect(importCycles()).toEqual([]);
  });

  it("builds no DOM by hand: no helpers of a ui/dom module, no replaceChildren", () => {
    const { calls, replaceChildren } = figures;
    expect({ calls, replaceChildren }).toEqual({ calls: 0, replaceChildren: 0 });
  });

  it("measures every kind of function, nested ones on their own, from first line to last", () => {
    const body = (n: number) => "  x += 1;\n".repeat(n);
    const text =
      `export function outer() {\n  let x = 0;\n${body(3)}  const inner = () => {\n${body(100)}  };\n}\n` +
      `class A {\n  method() {\n${body(2)}  }\n}\n`;
    const found = Object.fromEntries(functionLengths(text).map((f) => [f.name, f.lines]));
    expect(found).toEqual({ outer: 108, inner: 102, method: 4 });
  });

  it("finds an import circle, however long", () => {
    const dir = mkdtempSync(join(tmpdir(), "health-"));
    try {
      const files = ["a", "b", "c"].map((name) => join(dir, `${name}.ts`));
      writeFileSync(files[0]!, 'import { b } from "./b";\nexport const a = b;\n');
      writeFileSync(files[1]!, 'import { c } from "./c";\nexport const b = c;\n');
      writeFileSync(files[2]!, 'import type { a } from "./a";\nexport const c = 1 as unknown as typeof a;\n');
      expect(importCycles(files).map((cycle) => cycle.map((p) => p.split("/").pop()))).toEqual([
        ["a.ts", "b.ts", "c.ts", "a.ts"],
      ]);
      writeFileSync(files[2]!, "export const c = 1;\n");
      expect(importCycles(files)).toEqual([]);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  });
});
