// The WebAssembly runtime in Debian's chromium (headless, driven by puppeteer-core) gives the
// native C++ runtime's figures: the page loads the module and the export, replays the inputs of
// a reference file written natively by capi_reference (tests/capi: a part moved, a point grabbed,
// grabbed out of reach, released, the part moved back, updates) through the JavaScript API and
// compares every hose's properties, frame results, joint poses and surface with it, then checks
// the API's refusals (wasm_replay_check.mjs, which also states the tolerances and why).
//
//   node wasm_replay.mjs <wasm dir> <export.glb> <reference.txt>
//
// Exit 0: all agree; 1: differences (each printed); 77: skipped (no chromium, no WebAssembly
// build, or no export: the engine without ../shared).
import { existsSync } from 'node:fs';
import { basename, dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchChromium, newPage, requireBrowserAndWasm, serve, skip } from './browser.mjs';

const [wasmDir, exportFile, referenceFile] = process.argv.slice(2);
if (!referenceFile) {
  console.error('usage: node wasm_replay.mjs <wasm dir> <export.glb> <reference.txt>');
  process.exit(2);
}
requireBrowserAndWasm(resolve(wasmDir));
if (!existsSync(exportFile)) skip(`${exportFile} is absent (the engine samples need ../shared/scenes)`);
if (!existsSync(referenceFile)) skip(`${referenceFile} is absent (capi.reference.* writes it)`);

const server = await serve({
  '/wasm/': resolve(wasmDir), '/data/': dirname(resolve(exportFile)),
  '/reference/': dirname(resolve(referenceFile)), '/clients/': dirname(fileURLToPath(import.meta.url)),
}, { '/blank.html': '<!doctype html><link rel="icon" href="data:,"><title>wasm replay</title>' });
const browser = await launchChromium();
let outcome;
try {
  const page = await newPage(browser);
  await page.goto(`${server.url}/blank.html`);
  outcome = await page.evaluate(async (exportName, referenceName) => {
    const api = await import('/wasm/chaintube.mjs');
    const { replayReference, TOLERANCE } = await import('/clients/wasm_replay_check.mjs');
    const chaintube = await api.loadChainTube();
    const bytes = new Uint8Array(await (await fetch(`/data/${exportName}`)).arrayBuffer());
    const reference = await (await fetch(`/reference/${referenceName}`)).text();
    return { ...replayReference(api, chaintube, bytes, exportName, reference), tolerance: TOLERANCE,
      userAgent: navigator.userAgent };
  }, basename(exportFile), basename(referenceFile));
  outcome.failures.push(...page.problems);
} finally {
  await browser.close();
  await server.close();
}
for (const failure of outcome.failures) console.error(`FAIL ${failure}`);
console.log(`wasm_replay: ${exportFile} in ${outcome.userAgent.match(/(Headless)?Chrome\/[\d.]+/)?.[0]}: ` +
  `${outcome.compared} figures compared with the native runtime, largest difference ` +
  `${outcome.largest.toPrecision(3)} (tolerance ${outcome.tolerance}); gravity hoses' figures ` +
  `differ by up to ${outcome.largestGravity.toPrecision(3)} (measured, not compared); ${outcome.failures.length} failures`);
process.exit(outcome.failures.length === 0 ? 0 : 1);
