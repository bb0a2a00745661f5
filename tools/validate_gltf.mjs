// Validate glTF/GLB files with the Khronos glTF-Validator and print one JSON
// report per file (an array). Used by the test-suite; exits 0 even when a
// file has issues, so the caller decides what counts as failure.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
const validator = require('gltf-validator');

const reports = [];
for (const file of process.argv.slice(2)) {
  const data = new Uint8Array(await readFile(file));
  const dir = path.dirname(file);
  const report = await validator.validateBytes(data, {
    uri: path.basename(file),
    maxIssues: 200,
    externalResourceFunction: (uri) =>
      readFile(path.join(dir, decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  reports.push({ file, numErrors: report.issues.numErrors, numWarnings: report.issues.numWarnings,
    numInfos: report.issues.numInfos, messages: report.issues.messages });
}
process.stdout.write(JSON.stringify(reports));
