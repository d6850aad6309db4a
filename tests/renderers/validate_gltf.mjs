// Validates a .glb with the Khronos glTF validator (the npm package pinned in package.json),
// offline: `node validate_gltf.mjs IN.glb`. Prints the report's counts and messages as JSON;
// exits 1 when it finds any error, or when the file cannot be read.

import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const validator = require("gltf-validator");
const path = process.argv[2];
if (!path) {
  console.error("validate_gltf: usage: node validate_gltf.mjs IN.glb");
  process.exit(1);
}
const report = await validator.validateBytes(new Uint8Array(readFileSync(path)), {
  uri: path,
  maxIssues: 100,
  externalResourceFunction: () => Promise.reject(new Error("no external resources")),
});
const i = report.issues;
console.log(JSON.stringify({
  validator: report.validatorVersion,
  numErrors: i.numErrors,
  numWarnings: i.numWarnings,
  numInfos: i.numInfos,
  messages: i.messages.map((m) => `${m.severity} ${m.code} ${m.pointer || ""}: ${m.message}`),
}, null, 1));
process.exit(i.numErrors > 0 ? 1 : 0);
