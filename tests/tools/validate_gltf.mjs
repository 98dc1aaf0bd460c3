// Validates glTF files with the Khronos glTF validator (npm gltf-validator, pinned in ci/package.json).
//
// Usage: node tests/tools/validate_gltf.mjs FILE...
// Prints, per file, the number of errors, warnings, infos and hints, then each error with its JSON
// pointer. Exit status: 0 if no file has an error, 1 if any has, 2 for a usage or setup problem.
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const ciDir = path.resolve(here, '..', '..', 'ci');

let validator;
try {
  validator = createRequire(path.join(ciDir, 'package.json'))('gltf-validator');
} catch (e) {
  console.error(`validate_gltf: cannot load gltf-validator from ${ciDir}/node_modules (${e.message}).`);
  console.error('Install it with: ci/install-deps.sh validator   (or: cd ci && npm ci)');
  process.exit(2);
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node tests/tools/validate_gltf.mjs FILE...');
  process.exit(2);
}

async function validateFile(file) {
  const full = path.resolve(file);
  const bytes = new Uint8Array(fs.readFileSync(full));
  return validator.validateBytes(bytes, {
    uri: path.basename(full),
    maxIssues: 0,  // report every issue
    // Buffers and images referenced by relative URIs are read from beside the file.
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        const resource = path.resolve(path.dirname(full), decodeURIComponent(uri));
        fs.readFile(resource, (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
      }),
  });
}

let failed = false;
console.log(`gltf-validator ${validator.version()}`);
for (const file of files) {
  let report;
  try {
    report = await validateFile(file);
  } catch (e) {
    console.log(`${file}: cannot validate: ${e}`);
    failed = true;
    continue;
  }
  const issues = report.issues;
  const info = report.info ?? {};
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
              `${issues.numInfos} infos, ${issues.numHints} hints` + (issues.truncated ? ' (truncated)' : '') +
              ` [${info.drawCallCount ?? '?'} draw calls, ${info.totalTriangleCount ?? '?'} triangles]`);
  for (const m of issues.messages) {
    if (m.severity === 0) console.log(`  error ${m.code} at ${m.pointer ?? '(document)'}: ${m.message}`);
  }
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
