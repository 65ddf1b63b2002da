// Runs the Khronos glTF-Validator on exported files.
//   node validate.mjs [--allow CODE]… FILE.glb|FILE.gltf …
// Passes (exit 0) only if every file has 0 errors, 0 warnings, and no information or hint other
// than UNSUPPORTED_EXTENSION for our own CHAINTUBE_hose_rig extension (and infos/hints whose
// code is given with --allow, e.g. NODE_EMPTY for --joints-at-root exports, whose attachment
// target nodes may be empty locators). Prints one summary line
// per file and every offending message.
import validator from 'gltf-validator';
import { readFile } from 'node:fs/promises';
import path from 'node:path';

const ownExtension = 'CHAINTUBE_hose_rig';
const allowed = new Set();
const files = [];
for (let i = 2; i < process.argv.length; i++) {
  if (process.argv[i] === '--allow') allowed.add(process.argv[++i]);
  else files.push(process.argv[i]);
}
let failed = 0;
for (const file of files) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    writeTimestamp: false,
    externalResourceFunction: (uri) =>
      readFile(path.join(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const issues = report.issues;
  const unexpected = issues.messages.filter(
    (m) => !(m.code === 'UNSUPPORTED_EXTENSION' && m.message.includes(ownExtension)) &&
           !(m.severity >= 2 && allowed.has(m.code)));
  const ownExtensionReported = issues.messages.some(
    (m) => m.code === 'UNSUPPORTED_EXTENSION' && m.message.includes(ownExtension));
  const ok = issues.numErrors === 0 && issues.numWarnings === 0 && unexpected.length === 0;
  console.log(`${ok ? 'PASS' : 'FAIL'} ${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
              `${issues.numInfos} infos, ${issues.numHints} hints` +
              (ownExtensionReported ? ` (info UNSUPPORTED_EXTENSION ${ownExtension}, expected)` : '') +
              `; ${report.info?.totalVertexCount ?? '?'} vertices, ${report.info?.animationCount ?? 0} animations`);
  for (const m of unexpected.slice(0, 40))
    console.log(`  severity ${m.severity} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  if (!ok) failed++;
}
process.exit(failed ? 1 : 0);
