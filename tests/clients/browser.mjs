// What the browser tests share: a static file server for the viewer, the WebAssembly build and
// the exports, Debian's chromium driven headless by puppeteer-core, and the checks that decide
// whether a test can run at all (exit 77 = skipped, with the reason).
import { createServer } from 'node:http';
import { existsSync, createReadStream, statSync } from 'node:fs';
import { extname, join, normalize, resolve, sep } from 'node:path';
import puppeteer from 'puppeteer-core';

export const CHROMIUM = process.env.CHAINTUBE_CHROMIUM ?? '/usr/bin/chromium';

const MIME = {
  '.html': 'text/html; charset=utf-8', '.css': 'text/css; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8', '.mjs': 'text/javascript; charset=utf-8',
  '.json': 'application/json', '.wasm': 'application/wasm', '.glb': 'model/gltf-binary',
  '.gltf': 'model/gltf+json', '.bin': 'application/octet-stream', '.png': 'image/png',
};

/** Exits 77 (ctest: skipped) with the reason. */
export function skip(reason) {
  console.log(`skipped: ${reason}`);
  process.exit(77);
}

/** Skips unless chromium and the WebAssembly build (chaintube.mjs, chaintube_runtime.wasm in
 * wasmDir) are there. */
export function requireBrowserAndWasm(wasmDir) {
  if (!existsSync(CHROMIUM))
    skip(`${CHROMIUM} is absent (apt-get install chromium; ./build.sh test installs it)`);
  requireWasm(wasmDir);
}

export function requireWasm(wasmDir) {
  for (const file of ['chaintube.mjs', 'chaintube_runtime.mjs', 'chaintube_runtime.wasm'])
    if (!existsSync(join(wasmDir, file)))
      skip(`${join(wasmDir, file)} is absent: build the WebAssembly runtime with ` +
        '`cmake --preset wasm && cmake --build --preset wasm` (./build.sh does when emscripten is installed)');
}

/**
 * Serves folders over HTTP on 127.0.0.1 (a free port): mounts maps a URL prefix ('/wasm/') to a
 * folder ('/' serves everything else; without it other paths are 404); pages maps a path ('/blank.html') to an HTML text served as is.
 * Resolves to { url, close() }.
 */
export function serve(mounts, pages = {}) {
  const prefixes = Object.keys(mounts).sort((a, b) => b.length - a.length);
  const server = createServer((request, response) => {
    const path = decodeURIComponent(new URL(request.url, 'http://localhost').pathname);
    if (pages[path] !== undefined) {
      response.writeHead(200, { 'Content-Type': MIME['.html'] }).end(pages[path]);
      return;
    }
    const prefix = prefixes.find((p) => path.startsWith(p));
    if (prefix === undefined) {
      response.writeHead(404, { 'Content-Type': 'text/plain' }).end(`${path}: not found`);
      return;
    }
    const root = resolve(mounts[prefix]);
    const file = normalize(join(root, path.slice(prefix.length)));
    if (file !== root && !file.startsWith(root + sep)) {
      response.writeHead(403).end();
      return;
    }
    let stat = null;
    try { stat = statSync(file); } catch { /* absent */ }
    if (!stat || !stat.isFile()) {
      response.writeHead(404, { 'Content-Type': 'text/plain' }).end(`${path}: not found`);
      return;
    }
    response.writeHead(200, {
      'Content-Type': MIME[extname(file)] ?? 'application/octet-stream',
      'Content-Length': stat.size, 'Cache-Control': 'no-store',
    });
    createReadStream(file).pipe(response);
  });
  return new Promise((resolvePromise) => {
    server.listen(0, '127.0.0.1', () => resolvePromise({
      url: `http://127.0.0.1:${server.address().port}`,
      close: () => new Promise((done) => server.close(done)),
    }));
  });
}

/** Debian's chromium, headless, WebGL on SwiftShader; a 1280 x 800 window. */
export async function launchChromium() {
  return puppeteer.launch({
    executablePath: CHROMIUM,
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--window-size=1280,800'],
    defaultViewport: { width: 1280, height: 800, deviceScaleFactor: 1 },
  });
}

/** A new page whose console errors and page errors are collected in page.problems. */
export async function newPage(browser) {
  const page = await browser.newPage();
  page.problems = [];
  page.on('pageerror', (error) => page.problems.push(`page error: ${error.message}`));
  page.on('console', (message) => {
    if (message.type() === 'error') page.problems.push(`console error: ${message.text()}`);
  });
  return page;
}

/** Parses --name value pairs (and bare words as positional arguments). */
export function parseArguments(argv) {
  const options = { _: [] };
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i].startsWith('--')) options[argv[i].slice(2)] = argv[++i];
    else options._.push(argv[i]);
  }
  return options;
}
