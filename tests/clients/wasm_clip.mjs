// A hose through clips in Debian's chromium (headless, driven by puppeteer-core): the page loads
// the WebAssembly runtime and the motion-rig export, slides the carriage so that the cable
// carriage-cable slides through the carriage's clip, and checks the cable after every update
// through the JavaScript API (wasm_clip_check.mjs, which states the checks): through every
// clip's centre, every segment in its band, length conserved, every update OK; then the clip
// functions' refusals.
//
//   node wasm_clip.mjs <wasm dir> <motion-rig.glb>
//
// Exit 0: every check passes; 1: failures (each printed); 77: skipped (no chromium, no
// WebAssembly build, or no export).
import { existsSync } from 'node:fs';
import { basename, dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchChromium, newPage, requireBrowserAndWasm, serve, skip } from './browser.mjs';

const [wasmDir, exportFile] = process.argv.slice(2);
if (!exportFile) {
  console.error('usage: node wasm_clip.mjs <wasm dir> <motion-rig.glb>');
  process.exit(2);
}
requireBrowserAndWasm(resolve(wasmDir));
if (!existsSync(exportFile)) skip(`${exportFile} is absent (exporters.export_sample.motion-rig writes it)`);

const server = await serve({
  '/wasm/': resolve(wasmDir), '/data/': dirname(resolve(exportFile)),
  '/clients/': dirname(fileURLToPath(import.meta.url)),
}, { '/blank.html': '<!doctype html><link rel="icon" href="data:,"><title>wasm clip</title>' });
const browser = await launchChromium();
let outcome;
try {
  const page = await newPage(browser);
  await page.goto(`${server.url}/blank.html`);
  outcome = await page.evaluate(async (exportName) => {
    const api = await import('/wasm/chaintube.mjs');
    const { checkClips } = await import('/clients/wasm_clip_check.mjs');
    const chaintube = await api.loadChainTube();
    const bytes = new Uint8Array(await (await fetch(`/data/${exportName}`)).arrayBuffer());
    try {
      return { ...checkClips(api, chaintube, bytes, exportName), userAgent: navigator.userAgent };
    } catch (error) {
      return { checks: 0, failures: [`${error.name}: ${error.message}`], userAgent: navigator.userAgent };
    }
  }, basename(exportFile));
  outcome.failures.push(...page.problems);
} finally {
  await browser.close();
  await server.close();
}
for (const failure of outcome.failures) console.error(`FAIL ${failure}`);
console.log(`wasm_clip: ${exportFile} in ${outcome.userAgent.match(/(Headless)?Chrome\/[\d.]+/)?.[0]}: ` +
  `carriage-cable through its clips over ${outcome.frames} frames of the carriage (+-50 mm): the ` +
  `carriage clip's slide ${outcome.slideMin?.toFixed(4)} ... ${outcome.slideMax?.toFixed(4)} m ` +
  `(exported ${outcome.slideHome?.toFixed(4)}), ${outcome.checks} checks, ${outcome.failures.length} failures`);
process.exit(outcome.failures.length === 0 && outcome.checks > 0 ? 0 : 1);
