// The dashboard's code health in figures: how long each function of frontend/src is (the check in
// tests/code-health.test.ts fails on one over MAX_FUNCTION_LINES), how often views build their DOM by
// hand (calls of the helpers a file imports from a `ui/dom` module, and `replaceChildren`), and what
// each view releases.
//
//   node scripts/code-health.mjs        the longest functions and the counts, for frontend/src
//
// A function's length is the lines from its first to its last, nested functions included, as
// tests/test_code_health.py counts a Python function's (the generated src/api/schema.d.ts is left out).
import { readFileSync, readdirSync } from "node:fs";
import { dirname, join, relative, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import ts from "typescript";

export const MAX_FUNCTION_LINES = 100;

const here = dirname(fileURLToPath(import.meta.url));
export const SRC = resolve(here, "../src");

/** Every .ts file under `dir`, the generated API types left out. */
export function sourceFiles(dir = SRC) {
  const found = [];
  for (const entry of readdirSync(dir, { withFileTypes: true })) {
    const path = join(dir, entry.name);
    if (entry.isDirectory()) found.push(...sourceFiles(path));
    else if (entry.name.endsWith(".ts") && !entry.name.endsWith(".d.ts")) found.push(path);
  }
  return found.sort();
}

function nameOf(node) {
  if (node.name && ts.isIdentifier(node.name)) return node.name.text;
  if (node.name) return node.name.getText();
  const parent = node.parent;
  if (parent && ts.isVariableDeclaration(parent) && ts.isIdentifier(parent.name)) return parent.name.text;
  if (parent && ts.isPropertyAssignment(parent)) return parent.name.getText();
  return "(anonymous)";
}

/** Each function of a source text: { name, line, lines } (line: where it starts, 1-based). */
export function functionLengths(text, fileName = "probe.ts") {
  const source = ts.createSourceFile(fileName, text, ts.ScriptTarget.ES2022, true);
  const found = [];
  const visit = (node) => {
    if (ts.isFunctionLike(node) && "body" in node && node.body) {
      const start = source.getLineAndCharacterOfPosition(node.getStart(source)).line;
      const end = source.getLineAndCharacterOfPosition(node.getEnd()).line;
      found.push({ name: nameOf(node), line: start + 1, lines: end - start + 1 });
    }
    ts.forEachChild(node, visit);
  };
  visit(source);
  return found;
}

/** Calls of the helpers a file imports from a `ui/dom` module (h, s, section, ...), and its `replaceChildren`. */
export function domCalls(text, fileName = "probe.ts") {
  const source = ts.createSourceFile(fileName, text, ts.ScriptTarget.ES2022, true);
  const imported = new Set();
  for (const statement of source.statements) {
    if (!ts.isImportDeclaration(statement)) continue;
    const from = statement.moduleSpecifier.text;
    const named = statement.importClause?.namedBindings;
    if (/(^|\/)dom$/.test(from) && named && ts.isNamedImports(named)) {
      for (const element of named.elements) imported.add(element.name.text);
    }
  }
  let calls = 0;
  let replaceChildren = 0;
  const visit = (node) => {
    if (ts.isCallExpression(node)) {
      const callee = node.expression;
      if (ts.isIdentifier(callee) && imported.has(callee.text)) calls += 1;
      const name = ts.isIdentifier(callee)
        ? callee.text
        : ts.isPropertyAccessExpression(callee)
          ? callee.name.text
          : "";
      if (name === "replaceChildren") replaceChildren += 1;
    }
    ts.forEachChild(node, visit);
  };
  visit(source);
  return { calls, replaceChildren };
}

/** The relative imports of a source text, as paths resolved from `fileName` (".ts" added). */
export function importsOf(text, fileName) {
  const source = ts.createSourceFile(fileName, text, ts.ScriptTarget.ES2022, true);
  const found = [];
  for (const statement of source.statements) {
    const from =
      ts.isImportDeclaration(statement) || ts.isExportDeclaration(statement) ? statement.moduleSpecifier : null;
    if (from && ts.isStringLiteral(from) && from.text.startsWith(".") && !from.text.endsWith(".css")) {
      found.push(resolve(dirname(fileName), from.text.endsWith(".ts") ? from.text : `${from.text}.ts`));
    }
  }
  return found;
}

/** The import circles among `files` (each as the list of its modules, named from SRC), none when there are none. */
export function importCycles(files = sourceFiles()) {
  const graph = new Map(files.map((path) => [path, importsOf(readFileSync(path, "utf8"), path)]));
  const cycles = [];
  const state = new Map(); // path -> "open" while on the path being walked, "done" after
  const walk = (path, trail) => {
    state.set(path, "open");
    for (const next of graph.get(path) ?? []) {
      if (!graph.has(next)) continue;
      if (state.get(next) === "open")
        cycles.push([...trail.slice(trail.indexOf(next)), next].map((p) => relative(SRC, p)));
      else if (!state.has(next)) walk(next, [...trail, next]);
    }
    state.set(path, "done");
  };
  for (const path of files) if (!state.has(path)) walk(path, [path]);
  return cycles;
}

/** The figures over `files`: every function with its length, and the DOM-building counts. */
export function measure(files = sourceFiles()) {
  const functions = [];
  let calls = 0;
  let replaceChildren = 0;
  let filesWithCalls = 0;
  for (const path of files) {
    const text = readFileSync(path, "utf8");
    const name = relative(SRC, path);
    for (const f of functionLengths(text, path)) functions.push({ ...f, file: name });
    const dom = domCalls(text, path);
    calls += dom.calls;
    replaceChildren += dom.replaceChildren;
    if (dom.calls > 0) filesWithCalls += 1;
  }
  functions.sort((a, b) => b.lines - a.lines);
  return { functions, calls, filesWithCalls, replaceChildren };
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const { functions, calls, filesWithCalls, replaceChildren } = measure();
  console.log(`ui/dom helper calls: ${calls} in ${filesWithCalls} files; replaceChildren: ${replaceChildren}`);
  console.log(
    `functions: ${functions.length}; over ${MAX_FUNCTION_LINES} lines: ${functions.filter((f) => f.lines > MAX_FUNCTION_LINES).length}`,
  );
  console.log(`import circles: ${importCycles().length}`);
  console.log("the longest:");
  for (const f of functions.slice(0, 12))
    console.log(`  ${String(f.lines).padStart(4)}  ${f.file}:${f.line} ${f.name}`);
}
