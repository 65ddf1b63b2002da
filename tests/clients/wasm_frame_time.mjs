// The engine-50 frame in the browser against native, in one run: the same frame (every hose
// with free points has the point nearest its middle grabbed and walked, then update() and every
// hose's local joint poses; the walk of web_reference.cpp) timed natively through the C ABI
// (web_reference frames) and in Debian's chromium through the WebAssembly build's JavaScript
// API, alternating for --rounds rounds (default 3); prints each round's medians, the best median
// of each side, their ratio and the module's size. Measures, checks nothing: the
// figures go to exporters/README.md with the commit, date, machine and command.
//
//   node tests/clients/wasm_frame_time.mjs --wasm build-wasm/chaintube \
//     --reference build/tests/web/web_reference --export build/export/engine-50-hoses.glb [--frames 300] [--rounds 3]
import { execFileSync } from 'node:child_process';
import { readFileSync, statSync } from 'node:fs';
import { cpus, loadavg } from 'node:os';
import { basename, dirname, join, resolve } from 'node:path';
import { gzipSync } from 'node:zlib';
import { launchChromium, newPage, parseArguments, requireBrowserAndWasm, serve, skip } from './browser.mjs';

const options = parseArguments(process.argv.slice(2));
if (!options.wasm || !options.reference || !options.export) {
  console.error('usage: node wasm_frame_time.mjs --wasm DIR --reference EXE --export FILE.glb [--frames N]');
  process.exit(2);
}
const frames = Number(options.frames ?? 300);
const rounds = Number(options.rounds ?? 3);
requireBrowserAndWasm(resolve(options.wasm));
try { statSync(options.export); } catch { skip(`${options.export} is absent`); }

const wasm = readFileSync(join(options.wasm, 'chaintube_runtime.wasm'));
const loader = readFileSync(join(options.wasm, 'chaintube_runtime.mjs'));
const api = readFileSync(join(options.wasm, 'chaintube.mjs'));

const runNative = () => JSON.parse(execFileSync(options.reference, ['frames', options.export, String(frames)],
  { encoding: 'utf8' }));
const natives = [], webs = [];

const server = await serve({ '/wasm/': resolve(options.wasm), '/data/': dirname(resolve(options.export)) },
  { '/blank.html': '<!doctype html><link rel="icon" href="data:,"><title>frame time</title>' });
const browser = await launchChromium();
try {
  const page = await newPage(browser);
  await page.goto(`${server.url}/blank.html`);
  // Native and browser runs alternate, so that a load from other programs weighs on both.
  for (let round = 0; round < rounds; ++round) {
  natives.push(runNative());
  webs.push(await page.evaluate(async (file, frameCount) => {
    const { loadChainTube } = await import('/wasm/chaintube.mjs');
    const chaintube = await loadChainTube();
    const bytes = new Uint8Array(await (await fetch(`/data/${file}`)).arrayBuffer());
    const rig = chaintube.loadMemory(file, bytes);
    const hoses = rig.hoseCount();
    const infos = [...Array(hoses).keys()].map((h) => rig.hoseInfo(h));
    const walks = [];
    infos.forEach((info, h) => {
      if (info.grabbableCount === 0) return;
      const points = rig.grabbablePoints(h);
      const middle = info.pointCount >> 1;
      let point = points[0];
      for (const p of points) if (Math.abs(p - middle) < Math.abs(point - middle)) point = p;
      const world = rig.jointPosesF64(h, { local: false }).world;
      walks.push({ hose: h, point, laid: [0, 1, 2].map((c) => world[7 * point + c]), offset: [0, 0, 0],
        state: (0x9E3779B9 ^ (h + 1)) >>> 0 });
    });
    const next = (walk) => {
      let x = walk.state;
      x ^= x << 13; x ^= x >>> 17; x ^= x << 5;
      walk.state = x >>> 0;
      return walk.state;
    };
    const times = [];
    let checksum = 0;
    const target = [0, 0, 0];
    for (let f = 0; f < frameCount; ++f) {
      const start = performance.now();
      for (const walk of walks) {
        for (let c = 0; c < 3; ++c) {
          walk.offset[c] = Math.min(5, Math.max(-5, walk.offset[c] + (next(walk) % 3) - 1));
          target[c] = walk.laid[c] + walk.offset[c] * 0.01;
        }
        rig.grab(walk.hose, walk.point, target);
      }
      rig.update();
      const firsts = [];
      for (let h = 0; h < hoses; ++h)
        if (infos[h].jointCount > 0) firsts.push(rig.jointPoses(h, { world: false }).local[0]);
        else firsts.push(0);
      times.push(performance.now() - start);
      for (const x of firsts) checksum += x;
    }
    rig.destroy();
    const sorted = [...times].sort((a, b) => a - b);
    return { frames: frameCount, grabbed: walks.length, medianMs: sorted[sorted.length >> 1],
      meanMs: times.reduce((a, b) => a + b, 0) / times.length, checksum, userAgent: navigator.userAgent };
  }, basename(options.export), frames));
  }
} finally {
  await browser.close();
  await server.close();
}

const kib = (n) => `${(n / 1024).toFixed(0)} KiB`;
const best = (runs) => runs.reduce((a, b) => (b.medianMs < a.medianMs ? b : a));
const native = best(natives), web = best(webs);
console.log(`machine: ${cpus()[0].model}, ${cpus().length} CPUs, load average ${loadavg().map((x) => x.toFixed(1)).join(' ')}`);
console.log(`browser: ${web.userAgent}`);
console.log(`module: chaintube_runtime.wasm ${wasm.length} bytes (${kib(wasm.length)}, gzip ${kib(gzipSync(wasm).length)}); ` +
  `chaintube_runtime.mjs ${kib(loader.length)}, chaintube.mjs ${kib(api.length)}`);
console.log(`${basename(options.export)}: ${native.grabbed} hoses grabbed a frame, ${frames} frames, ${rounds} rounds alternating`);
natives.forEach((n, k) => console.log(`round ${k + 1}: native median ${n.medianMs.toFixed(2)} ms, ` +
  `chromium median ${webs[k].medianMs.toFixed(2)} ms, ratio ${(webs[k].medianMs / n.medianMs).toFixed(2)}`));
console.log(`native (C ABI):  best median ${native.medianMs.toFixed(2)} ms`);
console.log(`chromium (wasm): best median ${web.medianMs.toFixed(2)} ms`);
console.log(`browser / native: ${(web.medianMs / native.medianMs).toFixed(2)} (best medians)`);
console.log(`checksum (sum of every hose's first joint x over the frames): native ${native.checksum}, browser ${web.checksum}`);
