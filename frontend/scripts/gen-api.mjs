// Generates src/api/schema.d.ts, the dashboard's API types, from the server's OpenAPI schema.
//
//   npm run gen:api     rewrite the file
//   npm run check:api   exit 1 when the committed file differs from what the server's schema gives
//
// The schema comes straight from the app factory (no server is started, no learner thread, no
// viser): `create_app(...)` only builds routes; its lifespan, which starts the heavy parts, never runs.
// PYTHON names the interpreter (default: the repository's .venv).
import { execFileSync } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { dirname, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import openapiTS, { astToString } from "openapi-typescript";

const here = dirname(fileURLToPath(import.meta.url));
const frontend = resolve(here, "..");
const target = resolve(frontend, "src/api/schema.d.ts");
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

async function generate() {
  const json = execFileSync(python, ["-c", PRINT_SCHEMA], { encoding: "utf8", maxBuffer: 64 * 1024 * 1024 });
  const ast = await openapiTS(JSON.parse(json));
  return HEADER + astToString(ast);
}

const text = await generate();
if (process.argv.includes("--check")) {
  let committed = "";
  try {
    committed = readFileSync(target, "utf8");
  } catch {
    // a missing file is simply out of date
  }
  if (committed !== text) {
    console.error(`${target} is out of date with the server's OpenAPI schema: run \`npm run gen:api\` in frontend/`);
    process.exit(1);
  }
  console.log("src/api/schema.d.ts matches the server's OpenAPI schema");
} else {
  writeFileSync(target, text);
  console.log(`wrote ${target}`);
}
