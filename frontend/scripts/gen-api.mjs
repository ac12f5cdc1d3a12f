// Generates src/api/schema.d.ts, the dashboard's API types, and src/api/stream-protocol.ts, the
// WebSocket streams' close codes as values (from the schema's `StreamClose`, which the server builds
// from backend/horde/server/stream_protocol.py), from the server's OpenAPI schema.
//
//   npm run gen:api     rewrite the files
//   npm run check:api   exit 1 when a committed file differs from what the server's schema gives
//
// The schema comes straight from the app factory (no server is started, no learner thread, no
// viser): `create_app(...)` only builds routes; its lifespan, which starts the heavy parts, never runs.
// PYTHON names the interpreter (default: the repository's .venv).
import { execFileSync } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { dirname, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import openapiTS, { astToString } from "openapi-typescript";
import * as prettier from "prettier";

const here = dirname(fileURLToPath(import.meta.url));
const frontend = resolve(here, "..");
const target = resolve(frontend, "src/api/schema.d.ts");
const streamTarget = resolve(frontend, "src/api/stream-protocol.ts");
const python = process.env.PYTHON ?? resolve(frontend, "../.venv/bin/python");

const PRINT_SCHEMA = [
  "import json, tempfile",
  "from pathlib import Path",
  "from horde.server import Settings, create_app",
  "app = create_app(Settings(data=Path(tempfile.gettempdir()) / 'horde-openapi', token=None))",
  "print(json.dumps(app.openapi(), sort_keys=True))",
].join("\n");

const HEADER = `/**
 * The Horde Lab API, generated from the server's OpenAPI schema by \`npm run gen:api\`.
 * Do not edit: change the pydantic models in backend/horde and regenerate.
 */

`;

const STREAM_HEADER = `/**
 * The WebSocket streams' close codes, generated from the server's OpenAPI schema (\`StreamClose\`, built
 * from backend/horde/server/stream_protocol.py) by \`npm run gen:api\`. Do not edit.
 */
`;

/** The close codes as a frozen object of named values, each with its meaning. */
async function streamProtocol(schema) {
  const close = schema.components?.schemas?.StreamClose;
  const names = close?.["x-enum-varnames"];
  const meanings = close?.["x-enum-descriptions"] ?? [];
  if (!close || !Array.isArray(names) || names.length !== close.enum.length) {
    throw new Error(
      "the OpenAPI schema has no StreamClose with x-enum-varnames (backend/horde/server/stream_protocol.py)",
    );
  }
  const members = close.enum.map((code, i) => `  /** ${meanings[i] ?? ""} */\n  ${names[i]}: ${code},`).join("\n");
  const text =
    STREAM_HEADER +
    'import type { components } from "./schema";\n\n' +
    `export const StreamClose = {\n${members}\n} as const satisfies Record<string, components["schemas"]["StreamClose"]>;\n\n` +
    "export type StreamCloseCode = (typeof StreamClose)[keyof typeof StreamClose];\n";
  const options = (await prettier.resolveConfig(streamTarget)) ?? {};
  return prettier.format(text, { ...options, filepath: streamTarget });
}

async function generate() {
  const json = execFileSync(python, ["-c", PRINT_SCHEMA], { encoding: "utf8", maxBuffer: 64 * 1024 * 1024 });
  const schema = JSON.parse(json);
  const ast = await openapiTS(schema);
  return [
    [target, HEADER + astToString(ast)],
    [streamTarget, await streamProtocol(schema)],
  ];
}

const files = await generate();
if (process.argv.includes("--check")) {
  let stale = false;
  for (const [path, text] of files) {
    let committed = "";
    try {
      committed = readFileSync(path, "utf8");
    } catch {
      // a missing file is simply out of date
    }
    if (committed !== text) {
      console.error(`${path} is out of date with the server's OpenAPI schema: run \`npm run gen:api\` in frontend/`);
      stale = true;
    }
  }
  if (stale) process.exit(1);
  console.log("src/api/schema.d.ts and src/api/stream-protocol.ts match the server's OpenAPI schema");
} else {
  for (const [path, text] of files) {
    writeFileSync(path, text);
    console.log(`wrote ${path}`);
  }
}
