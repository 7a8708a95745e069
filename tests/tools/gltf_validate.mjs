// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Runs the Khronos glTF-Validator (npm gltf-validator) on each file named and prints one line per file:
// "PATH errors E warnings W infos I", then every error and warning. Exit status 1 if any file has an error.
// Usage: node gltf_validate.mjs VALIDATOR_MODULE_DIR FILE...
import { createRequire } from 'module';
import fs from 'fs';
import path from 'path';

const [moduleDir, ...files] = process.argv.slice(2);
const validator = createRequire(import.meta.url)(path.resolve(moduleDir));
let failed = false;
for (const file of files) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        try { resolve(new Uint8Array(fs.readFileSync(path.join(path.dirname(file), decodeURIComponent(uri))))); }
        catch (e) { reject(e.toString()); }
      }),
  });
  const n = report.issues;
  console.log(`${file} errors ${n.numErrors} warnings ${n.numWarnings} infos ${n.numInfos}`);
  for (const m of n.messages)
    if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  if (n.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
