// The web viewer (exporters/viewer) in Debian's chromium, headless, driven by puppeteer-core.
//
//   node viewer_test.mjs rig --repo DIR --wasm DIR --reference EXE --export FILE.glb --out DIR
//                        [--part NAME] [--clips N] [--reel HOSE]
//       opens the export (?file=…&record=1), checks the panel lists every hose, drags a hose
//       point with the mouse (a press on the hose, a move, screenshots before and while held,
//       the release), clicks the part NAME (default: the part most hoses are fixed to) and drags
//       its gizmo's X arrow; then replays the viewer's recorded runtime inputs natively (EXE
//       replay: the C ABI) and checks that every bone's world position equals the native
//       joint's to 1e-5 m, that the grabbed point followed the mouse and that the joints fixed
//       to the part moved with it. With --clips N: the rig has N clips, each drawn as a ring
//       around the hose (its centre on the held segment's line to 1e-5 m, its normal along the
//       segment), before and after the part move; a ring on the moved part moved with it.
//       With --reel HOSE: a click on the hose's panel row selects it, holding ] pays it out and
//       [ reels it in (the viewer's keys), frames of the same reel take it 0.3 m beyond its
//       exported length and back in at the speed asked to it (screenshots
//       <export>-reeled-out.png, -reeled-back.png); the native replay then covers the reels too (a snapshot after them).
//   node viewer_test.mjs sockets --repo DIR --wasm DIR --reference EXE --export test-rig.glb --out DIR
//       the test rig's sockets: a press near left-feed's valve end selects it, U unplugs it; the
//       end dragged with the mouse onto plate-port (its ring) is guided in and, let go, snaps in
//       (the runtime's capture: the socket drawn blue, the end on it); U unplugs it again and a
//       drag onto valve-outlet plugs it there (snapped in, or plugged by the viewer when the
//       guided end's segment is beyond the capture angle: the run says which); the recorded
//       inputs (grabs, releases, plugs, unplugs, updates) replayed natively put every bone where
//       the native runtime puts its joint (1e-5 m).
//   node viewer_test.mjs bad-file --repo DIR --wasm DIR --out DIR
//       opens a file that is not a GLB, a glTF without a hose rig and a missing file: the page
//       shows a message naming the file and the reason (not a blank canvas).
//
// Screenshots go to --out (<export>-before-drag.png, <export>-drag.png, <export>-part-moved.png,
// bad-file.png; sockets: sockets-guided.png, sockets-plate.png, sockets-outlet.png). Exit 0: passed; 1: failed; 77: skipped (no chromium, no WebAssembly build, no
// export, no node_modules).
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, writeFileSync } from 'node:fs';
import { basename, dirname, join, resolve } from 'node:path';
import { launchChromium, newPage, parseArguments, requireBrowserAndWasm, serve, skip } from './browser.mjs';

const TOLERANCE = 1e-5; // metres

const options = parseArguments(process.argv.slice(2));
const mode = options._[0];
if (!['rig', 'sockets', 'bad-file'].includes(mode) || !options.repo || !options.wasm || !options.out) {
  console.error('usage: node viewer_test.mjs rig|sockets|bad-file --repo DIR --wasm DIR --out DIR ' +
    '[--reference EXE --export FILE.glb]');
  process.exit(2);
}
const repo = resolve(options.repo);
requireBrowserAndWasm(resolve(options.wasm));
if (!existsSync(join(repo, 'exporters/viewer/node_modules/three')))
  skip('exporters/viewer/node_modules is absent: run npm ci in exporters/viewer (./build.sh does)');
if (mode !== 'bad-file' && !existsSync(options.export))
  skip(`${options.export} is absent (the engine samples need ../shared/scenes)`);
mkdirSync(options.out, { recursive: true });

let failures = 0;
function check(condition, what) {
  console.log(`${condition ? 'ok  ' : 'FAIL'} ${what}`);
  if (!condition) ++failures;
}

// The clip rings as drawn against the hoses' bones: every ring centred on the line of the
// segment its clip holds (metres) and its normal along that segment (sine of the angle).
function ringsOnHoses(rings, snapshot) {
  let offLine = 0, offAxis = 0;
  for (const ring of rings) {
    const joints = snapshot.hoses.find((h) => h.id === ring.hose).joints;
    const a = joints[ring.segment], b = joints[ring.segment + 1];
    const d = b.map((x, k) => x - a[k]);
    const length = Math.hypot(...d);
    const u = d.map((x) => x / length);
    const r = ring.centre.map((x, k) => x - a[k]);
    const along = r.reduce((sum, x, k) => sum + x * u[k], 0);
    offLine = Math.max(offLine, Math.hypot(...r.map((x, k) => x - along * u[k])));
    const n = ring.axis;
    offAxis = Math.max(offAxis, Math.hypot(n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2],
      n[0] * u[1] - n[1] * u[0]));
  }
  return { offLine, offAxis };
}
// The same inputs natively: every bone where the native runtime puts its joint.
function compareWithNative(after, stem) {
  const inputsFile = join(options.out, `${stem}-inputs.json`);
  writeFileSync(inputsFile, JSON.stringify(after.inputs));
  const expected = JSON.parse(execFileSync(options.reference, ['replay', options.export, inputsFile],
    { encoding: 'utf8', maxBuffer: 64 << 20 }));
  let largest = 0, joints = 0, mismatch = null;
  check(expected.hoses.length === after.hoses.length, 'the native runtime has the same hoses');
  expected.hoses.forEach((native, h) => {
    const browserHose = after.hoses[h];
    if (browserHose?.id !== native.id || browserHose.joints.length !== native.joints.length) {
      mismatch ??= `hose ${h}: ${browserHose?.id} with ${browserHose?.joints.length} joints in the browser, ` +
        `${native.id} with ${native.joints.length} natively`;
      return;
    }
    native.joints.forEach((position, j) => {
      ++joints;
      const difference = Math.max(...position.map((x, k) => Math.abs(x - browserHose.joints[j][k])));
      if (!(difference <= largest)) largest = difference;
      if (!(difference <= TOLERANCE)) mismatch ??= `${native.id} joint ${j}: browser ` +
        `${browserHose.joints[j].join(', ')}, native ${position.join(', ')}`;
    });
  });
  check(mismatch === null && joints > 0, `${joints} bones where the native runtime puts their joints after the ` +
    `same ${after.inputs.length} inputs (largest difference ${largest.toExponential(2)} m, tolerance ${TOLERANCE} m)` +
    (mismatch ? `: ${mismatch}` : ''));
}
const dataDir = mode !== 'bad-file' ? dirname(resolve(options.export)) : resolve(options.out);
const server = await serve({ '/': repo, '/wasm/': resolve(options.wasm), '/data/': dataDir });
const browser = await launchChromium();
try {
  const page = await newPage(browser);
  const viewerUrl = (file) => `${server.url}/exporters/viewer/index.html?` +
    new URLSearchParams({ file: `/data/${file}`, runtime: '/wasm/chaintube.mjs', record: '1' });
  const viewer = (f, ...args) => page.evaluate(f, ...args);
  const settle = async (frames = 3) => {
    const start = await viewer(() => window.chaintubeViewer.frames);
    await page.waitForFunction((n) => window.chaintubeViewer.frames >= n, { timeout: 60000 }, start + frames);
  };

  if (mode === 'bad-file') {
    writeFileSync(join(dataDir, 'not-a-rig.glb'), 'This is a text file, not a GLB.\n');
    writeFileSync(join(dataDir, 'no-hoses.gltf'), JSON.stringify({
      asset: { version: '2.0' }, scenes: [{ nodes: [0] }], nodes: [{ name: 'box' }],
    }));
    const cases = [
      ['not-a-rig.glb', /not-a-rig\.glb/, 'the runtime\'s reason (malformed glTF)', /malformed/i],
      ['no-hoses.gltf', /no-hoses\.gltf/, 'the missing CHAINTUBE_hose_rig descriptor', /CHAINTUBE_hose_rig|hoses\.json/],
      ['missing.glb', /missing\.glb/, 'the server\'s 404', /404/],
    ];
    for (const [file, names, reasonText, reason] of cases) {
      await page.goto(viewerUrl(file));
      await page.waitForFunction(() => ['loaded', 'error'].includes(window.chaintubeViewer.state),
        { timeout: 60000 });
      const shown = await page.$eval('#message', (box) => ({
        visible: !box.hidden && box.getBoundingClientRect().width > 0, text: box.textContent,
      }));
      console.log(`${file}: "${shown.text.replace(/\n+/g, ' / ')}"`);
      check(shown.visible, `${file}: a message is shown on the page`);
      check(names.test(shown.text) && /Could not open/.test(shown.text), `${file}: it names the file`);
      check(reason.test(shown.text), `${file}: it gives ${reasonText}`);
      check(await viewer(() => window.chaintubeViewer.state) === 'error', `${file}: the viewer reports an error`);
      if (file === 'not-a-rig.glb') await page.screenshot({ path: join(options.out, 'bad-file.png') });
    }
    // chromium logs the 404 of missing.glb as a console error: expected here
    page.problems = page.problems.filter((problem) => !/Failed to load resource.*404/.test(problem));
  } else if (mode === 'rig') {
    const name = basename(options.export);
    const stem = name.replace(/\.glb$/, '');
    await page.goto(viewerUrl(name));
    await page.waitForFunction(() => ['loaded', 'error'].includes(window.chaintubeViewer.state),
      { timeout: 120000 });
    const state = await viewer(() => [window.chaintubeViewer.state, window.chaintubeViewer.message]);
    if (state[0] !== 'loaded') throw new Error(`the viewer did not load ${name}: ${state[1]}`);
    await settle();

    const panel = await viewer(() => window.chaintubeViewer.panel());
    const first = await viewer(() => window.chaintubeViewer.snapshot());
    check(panel.length === first.hoses.length && panel.length > 0,
      `the panel lists every hose (${panel.length} rows, ${first.hoses.length} hoses)`);
    check(panel.every((row) => ['ok', 'clamped', 'infeasible', 'static'].includes(row.status)),
      'every row has a status');
    check(panel.every((row) => row.tension.split(' ').filter(Boolean)
      .every((word) => Number(word) >= 0 && Number(word) <= 1)) &&
      panel.some((row) => row.tension !== ''),
    `the panel shows each attachment's tension, 0 ... 1 (${panel.map((row) => `${row.id}: ${row.tension}`).join('; ')})`);
    const vrButton = await page.$eval('#VRButton', (button) => button.textContent).catch(() => null);
    check(vrButton !== null, `three.js's VR button is on the page ("${vrButton}": no headset here)`);
    await page.screenshot({ path: join(options.out, `${stem}-before-drag.png`) });
    const clips = Number(options.clips ?? 0);
    const ringsBefore = await viewer(() => window.chaintubeViewer.clipRings());
    if (clips > 0) {
      check(await viewer(() => window.chaintubeViewer.clipCount()) === clips && ringsBefore.length === clips,
        `the rig has ${clips} clips, each drawn as a ring (${ringsBefore.length} rings)`);
      const on = ringsOnHoses(ringsBefore, first);
      check(on.offLine <= TOLERANCE && on.offAxis <= 1e-4 && ringsBefore.every((r) => r.gap <= 1e-6),
        `every ring around its hose: centre ${on.offLine.toExponential(2)} m off the held segment's line, ` +
        `normal ${on.offAxis.toExponential(2)} off its direction, every clip met`);
    }

    // The drag: the first hose whose middle free point the mouse hits on the screen.
    const target = await viewer(() => {
      const v = window.chaintubeViewer;
      for (const hose of v.hoseIds()) {
        const points = v.grabbablePoints(hose);
        if (points.length === 0) continue;
        const point = points[points.length >> 1];
        const at = v.screenOfPoint(hose, point);
        const picked = v.pickAt(at.x, at.y);
        if (picked?.hose === hose && at.x > 50 && at.x < 900 && at.y > 80 && at.y < 700)
          return { hose, point, ...at };
      }
      return null;
    });
    if (!target) throw new Error('no hose point is visible to drag');
    const picked = await viewer((t) => window.chaintubeViewer.pickAt(t.x, t.y), target);
    console.log(`dragging hose ${target.hose} from (${target.x.toFixed(0)}, ${target.y.toFixed(0)}), ` +
      `nearest grabbable point ${picked.point}`);
    const startPosition = first.hoses.find((h) => h.id === target.hose).joints[picked.point];
    await page.mouse.move(target.x, target.y);
    await page.mouse.down();
    for (let k = 1; k <= 10; ++k) {
      await page.mouse.move(target.x + 6 * k, target.y - 4 * k);
      await settle(1);
    }
    await settle(2);
    await page.screenshot({ path: join(options.out, `${stem}-drag.png`) });
    const held = await viewer(() => window.chaintubeViewer.panel());
    await page.mouse.up();
    await settle(2);
    const dragged = await viewer(() => window.chaintubeViewer.snapshot());
    const endPosition = dragged.hoses.find((h) => h.id === target.hose).joints[picked.point];
    const moved = Math.hypot(...endPosition.map((x, k) => x - startPosition[k]));
    check(moved > 0.01, `the grabbed point followed the mouse (${(100 * moved).toFixed(1)} cm)`);
    check(dragged.inputs.some((i) => i.op === 'grab' && i.point === picked.point) &&
      dragged.inputs.some((i) => i.op === 'release'), 'the drag grabbed the picked point and released it');
    console.log(`while held the panel said: ${JSON.stringify(held.find((r) => r.id === target.hose))}`);

    // The part move: click the part most hoses are fixed to, drag its gizmo's X arrow.
    const part = await viewer((name) => window.chaintubeViewer.parts().find((p) => name === undefined || p.name === name) ?? null,
      options.part);
    if (!part) throw new Error(options.part ? `no part named ${options.part} has hoses fixed to it` : 'no part has hoses fixed to it');
    const onPart = await viewer((p) => window.chaintubeViewer.screenOnPart(p), part.name);
    if (!onPart) throw new Error(`part ${part.name} is nowhere visible`);
    await page.mouse.click(onPart.x, onPart.y);
    await settle(2);
    check(await viewer(() => window.chaintubeViewer.selectedPart) === part.name,
      `a click on part "${part.name}" selects it`);
    const handle = await viewer(() => window.chaintubeViewer.gizmoHandle('X'));
    await page.mouse.move(handle.x - 1, handle.y);
    await page.mouse.move(handle.x, handle.y);
    await settle(1);
    check(await viewer(() => window.chaintubeViewer.gizmoAxis) === 'X', 'the mouse is over the gizmo\'s X arrow');
    const beforeMove = await viewer(() => window.chaintubeViewer.snapshot());
    const length = Math.hypot(handle.dx, handle.dy);
    await page.mouse.down();
    for (let k = 1; k <= 8; ++k) {
      await page.mouse.move(handle.x + 5 * k * handle.dx / length, handle.y + 5 * k * handle.dy / length);
      await settle(1);
    }
    await page.mouse.up();
    await settle(3);
    await page.screenshot({ path: join(options.out, `${stem}-part-moved.png`) });
    const after = await viewer(() => window.chaintubeViewer.snapshot());
    const moves = after.inputs.filter((i) => i.op === 'move' && i.node === part.node);
    check(moves.length > 0, `the gizmo moved part "${part.name}" in the runtime (${moves.length} moves)`);
    // The joints fixed to the part moved with it (as far as the part's origin moved).
    const partShift = moves.length ? Math.hypot(...moves.at(-1).trs.slice(0, 3).map((x, k) => x - part.trs[k])) : 0;
    let fixedShift = 0;
    for (const { hose, joint } of part.fixedJoints) {
      const a = beforeMove.hoses.find((h) => h.id === hose).joints[joint];
      const b = after.hoses.find((h) => h.id === hose).joints[joint];
      fixedShift = Math.max(fixedShift, Math.hypot(...b.map((x, k) => x - a[k])));
    }
    check(partShift > 0.005 && fixedShift > 0.5 * partShift,
      `the fixed segments follow the part (part ${(100 * partShift).toFixed(1)} cm, joints up to ${(100 * fixedShift).toFixed(1)} cm)`);
    if (clips > 0) {
      // The rings of clips on the moved part moved as far as its origin did (a move, no turn);
      // every ring still around its hose.
      const ringsAfter = await viewer(() => window.chaintubeViewer.clipRings());
      const carried = ringsAfter.filter((ring, r) => partShift > 0.005 && Math.abs(Math.hypot(...ring.centre.map((x, k) =>
        x - ringsBefore[r].centre[k])) - partShift) <= 1e-6);
      check(carried.length > 0, `${carried.length} ring(s) moved with part "${part.name}" by ` +
        `${(100 * partShift).toFixed(1)} cm (to 1e-6 m)`);
      const on = ringsOnHoses(ringsAfter, after);
      check(on.offLine <= TOLERANCE && on.offAxis <= 1e-4,
        `after the move every ring is around its hose: centre ${on.offLine.toExponential(2)} m off the held ` +
        `segment's line, normal ${on.offAxis.toExponential(2)} off its direction`);
      console.log(`the rings after the move: ${JSON.stringify(ringsAfter.map((r) => ({ hose: r.hose, clip: r.clip, segment: r.segment, gap: r.gap })))}`);
    }

    if (options.reel) {
      // Reel: a click on the hose's panel row selects it; ] held pays it out, [ reels it in;
      // then frames of the same reel (the hook) take it to 0.3 m beyond its exported length
      // (the viewer's bound) and back to it.
      const hose = options.reel, step = 0.5 / 90;
      const lengthOf = () => viewer((id) => window.chaintubeViewer.hoseLength(id), hose);
      const exported = (await lengthOf()).restLength;
      const row = await page.$(`#hoses tr[data-hose="${hose}"] td`);
      await row.click();
      check(await viewer(() => window.chaintubeViewer.selectedHose) === hose,
        `a click on ${hose}'s row selects it for the reel keys`);
      await page.keyboard.down(']');
      await settle(4);
      await page.keyboard.up(']');
      await settle(1);
      const keyed = await lengthOf();
      check(keyed.restLength > exported + step - 1e-12,
        `holding ] pays ${hose} out (${(1000 * (keyed.restLength - exported)).toFixed(1)} mm)`);
      await viewer(() => window.chaintubeViewer.reelFrames(60, +1));
      await settle(1);
      const out = await lengthOf();
      check(Math.abs(out.restLength - (exported + 0.3)) <= 1e-9,
        `${hose} paid out to 0.3 m beyond its exported length (${out.restLength.toFixed(6)} m, ` +
        `${out.pointCount} points; exported ${exported.toFixed(6)} m)`);
      await page.screenshot({ path: join(options.out, `${stem}-reeled-out.png`) });
      await page.keyboard.down('[');
      await settle(3);
      await page.keyboard.up('[');
      await settle(1);
      const inKeyed = await lengthOf();
      check(inKeyed.restLength < out.restLength - step + 1e-12, `holding [ reels ${hose} in`);
      const inFrames = Math.round((inKeyed.restLength - exported) / step);
      await viewer((frames) => window.chaintubeViewer.reelFrames(frames, -1), inFrames);
      await settle(1);
      // Reeling in keeps the speed asked where the hose beyond the outlet is bent (lib/README.md,
      // "Reel in, pay out"): the whole 0.3 m comes back, down to the exported length.
      const back = await lengthOf();
      check(Math.abs(back.restLength - (inKeyed.restLength - inFrames * step)) <= 1e-9 &&
        Math.abs(back.restLength - exported) <= step / 2,
        `${hose} reeled back in at the speed asked, every frame, to its exported length: ` +
        `${(1000 * (out.restLength - back.restLength)).toFixed(1)} of 300 mm ` +
        `(${back.restLength.toFixed(6)} m, exported ${exported.toFixed(6)} m, ${back.pointCount} points)`);
      await page.screenshot({ path: join(options.out, `${stem}-reeled-back.png`) });
    }

    compareWithNative(options.reel ? await viewer(() => window.chaintubeViewer.snapshot()) : after,
      stem);
  } else if (mode === 'sockets') {
    await page.goto(viewerUrl(basename(options.export)));
    await page.waitForFunction(() => ['loaded', 'error'].includes(window.chaintubeViewer.state),
      { timeout: 120000 });
    const state = await viewer(() => [window.chaintubeViewer.state, window.chaintubeViewer.message]);
    if (state[0] !== 'loaded') throw new Error(`the viewer did not load the export: ${state[1]}`);
    await settle();
    const hoseId = 'left-feed';
    const sockets = await viewer(() => window.chaintubeViewer.sockets());
    check(sockets.length === 2 && sockets.every((socket) => socket.occupant === null),
      `the rig's ${sockets.length} sockets are drawn, free (${sockets.map((socket) => socket.id).join(', ')})`);
    const count = (await viewer(() => window.chaintubeViewer.snapshot())).hoses.find((h) => h.id === hoseId).joints.length;
    const last = count - 1;

    // A press on the hose near its valve end selects that end; U unplugs it.
    const near = await viewer((id, point) => window.chaintubeViewer.screenOfPoint(id, point), hoseId, last - 2);
    await page.mouse.click(near.x, near.y);
    await settle(2);
    const selected = await viewer(() => window.chaintubeViewer.selectedEnd);
    check(selected?.hose === hoseId && selected?.end === 1, `a press near ${hoseId}'s valve end selects it (${JSON.stringify(selected)})`);
    await page.keyboard.press('u');
    await settle(2);
    const freeEnd = (await viewer((id) => window.chaintubeViewer.grabbablePoints(id), hoseId)).includes(last);
    check(freeEnd, `U unplugged it: point ${last} is free to grab`);

    // Drag the end onto a socket's ring and let go there: it snaps in.
    const plugInto = async (socketId, shot) => {
      // A press on the hose a few points from its free end takes the end point (the end point
      // itself may be inside a part).
      const from = await viewer((id, last) => {
        const v = window.chaintubeViewer;
        for (let point = last; point >= last - 3; --point) {
          const at = v.screenOfPoint(id, point);
          const picked = v.pickAt(at.x, at.y);
          if (picked?.hose === id) return { ...at, picked };
        }
        return null;
      }, hoseId, last);
      check(from?.picked.point === last, `a press near the free end picks point ${last} (${JSON.stringify(from?.picked)})`);
      if (!from) return;
      const to = await viewer((id) => window.chaintubeViewer.screenOfSocket(id), socketId);
      await page.mouse.move(from.x, from.y);
      await page.mouse.down();
      for (let k = 1; k <= 10; ++k) {
        await page.mouse.move(from.x + (to.x - from.x) * k / 10, from.y + (to.y - from.y) * k / 10);
        await settle(1);
      }
      await settle(40); // the guide brings it over the socket and down its axis
      check(await viewer(() => window.chaintubeViewer.guidedInto) === socketId, `the dragged end is guided into ${socketId}`);
      await page.screenshot({ path: join(options.out, shot.replace('.png', '-guided.png')) });
      const opsBefore = (await viewer(() => window.chaintubeViewer.snapshot())).inputs.length;
      await page.mouse.up();
      await settle(60); // it eases in (over kSnapSeconds, 5 updates at 90 Hz, then what the budget left pending)
      await page.screenshot({ path: join(options.out, shot) });
      const drawn = await viewer(() => window.chaintubeViewer.sockets());
      const socket = drawn.find((s) => s.id === socketId);
      const joints = (await viewer(() => window.chaintubeViewer.snapshot())).hoses.find((h) => h.id === hoseId).joints;
      const gap = Math.hypot(...joints[last].map((x, k) => x - socket.position[k]));
      check(socket.occupant?.hose === hoseId && socket.occupant?.end === 1 && socket.colour === 0x3c8cf0,
        `let go over ${socketId}, the end plugs in: the socket holds ${JSON.stringify(socket.occupant)}, drawn blue`);
      check(gap <= TOLERANCE, `the end sits on ${socketId} (${gap.toExponential(2)} m off)`);
      const ops = (await viewer(() => window.chaintubeViewer.snapshot())).inputs.slice(opsBefore).map((i) => i.op);
      return ops.includes('plug') ? 'plugged by the viewer (its segment beyond the capture angle)' : 'snapped in on release';
    };
    const intoPlate = await plugInto('plate-port', 'sockets-plate.png');
    check(intoPlate === 'snapped in on release', `plate-port: ${intoPlate}`);
    await page.keyboard.press('u');
    await settle(2);
    const unplugged = await viewer(() => window.chaintubeViewer.sockets());
    check(unplugged.every((socket) => socket.occupant === null), 'U unplugged it from plate-port: every socket is free');
    const intoOutlet = await plugInto('valve-outlet', 'sockets-outlet.png');
    console.log(`valve-outlet: ${intoOutlet}`);
    const after = await viewer(() => window.chaintubeViewer.snapshot());
    const ops = after.inputs.map((i) => i.op);
    check(ops.filter((op) => op === 'unplug').length === 2 && ops.filter((op) => op === 'release').length >= 2,
      `the inputs recorded: ${ops.filter((op) => op === 'unplug').length} unplugs, ` +
      `${ops.filter((op) => op === 'release').length} releases, ${ops.filter((op) => op === 'plug').length} plugs`);
    compareWithNative(after, 'sockets');
  }
  check(page.problems.length === 0, `no errors in the page${page.problems.length ? ': ' + page.problems.join('; ') : ''}`);
} catch (error) {
  console.log(`FAIL ${error.stack ?? error}`);
  ++failures;
} finally {
  await browser.close();
  await server.close();
}
console.log(failures === 0 ? 'viewer_test: passed' : `viewer_test: ${failures} failures`);
process.exit(failures === 0 ? 0 : 1);
