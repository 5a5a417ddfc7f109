// Runs the Khronos glTF validator on one .glb or .gltf and prints its counts and messages
// as one JSON line: {"errors":N,"warnings":N,"infos":N,"messages":[...]}.
// A peer for kapaint's tests (tests/peers.rs), never part of the product.
import { readFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import validator from 'gltf-validator';

const file = process.argv[2];
const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
  uri: file,
  maxIssues: 200,
  externalResourceFunction: (uri) =>
    Promise.resolve(new Uint8Array(readFileSync(join(dirname(file), decodeURIComponent(uri))))),
});
const issues = report.issues;
console.log(JSON.stringify({
  errors: issues.numErrors,
  warnings: issues.numWarnings,
  infos: issues.numInfos,
  messages: issues.messages.map((m) => `${m.severity} ${m.code} ${m.pointer ?? ''}: ${m.message}`),
}));
