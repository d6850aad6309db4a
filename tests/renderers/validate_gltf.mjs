// Validates a .glb (or .gltf without external resources) with the Khronos glTF validator, the
// npm package gltf-validator that package-lock.json pins, offline:
//
//   node validate_gltf.mjs IN.glb
//
// Prints the report's summary as one JSON object on stdout: {"validator": "...", "numErrors",
// "numWarnings", "numInfos", "numHints", "messages": ["SEVERITY CODE POINTER: message", ...]}
// (severity 0 error, 1 warning, 2 info, 3 hint; at most 100 messages). Exits 1 when the
// report has an error, or with one line on stderr when the file cannot be read or is not glTF
// at all; 0 otherwise. External resources (URIs) are refused: an exported .glb holds its
// images in its binary chunk.

import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

const die = (msg) => {
  console.error(`validate_gltf: ${String(msg).split("\n")[0]}`);
  process.exit(1);
};
const path = process.argv[2];
if (!path || process.argv.length !== 3) die("usage: node validate_gltf.mjs IN.glb");
let validator;
try {
  validator = createRequire(import.meta.url)("gltf-validator");
} catch (e) {
  die(`no gltf-validator (npm ci in tests/renderers): ${e.message}`);
}
let bytes;
try {
  bytes = new Uint8Array(readFileSync(path));
} catch (e) {
  die(`cannot read ${path}: ${e.message}`);
}
const report = await validator
  .validateBytes(bytes, {
    uri: path,
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      Promise.reject(new Error(`external resource ${uri} refused (offline)`)),
  })
  .catch((e) => die(`${path}: ${e.message || e}`));
const i = report.issues;
console.log(
  JSON.stringify({
    validator: `${report.validatorVersion}`,
    numErrors: i.numErrors,
    numWarnings: i.numWarnings,
    numInfos: i.numInfos,
    numHints: i.numHints,
    messages: i.messages.map((m) => `${m.severity} ${m.code} ${m.pointer || ""}: ${m.message}`),
  }),
);
process.exit(i.numErrors > 0 ? 1 : 0);
