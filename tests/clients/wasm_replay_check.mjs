// The check of wasm_replay.mjs, run inside the browser: replays the inputs of a reference file
// written by capi_reference (tests/capi: the native C++ runtime on the same export) through the
// JavaScript API (chaintube.mjs) and compares every hose's properties, frame results, joint
// poses and surface with the native figures; then checks the API's refusals and that the
// per-frame outputs are views of the module's memory. No file or Node API: the caller hands it
// the module and the bytes.
//
// Tolerances. The native runtime runs x86-64 double arithmetic, the module WebAssembly's: both
// are IEEE 754 doubles, but libm (sin, cos, acos, atan2 in the bend and twist code) and the
// order of a few sums differ in the last bits, and the differences grow along a hose's chain of
// points (measured: at most 2e-12). Positions, quaternion components and angles are compared to
// 1e-9 (metres, radians; the C ABI tests' tolerance), float32 surface vertices to 1e-6 (a few
// float ulps), sums over a whole surface to 1e-5; counts and statuses exactly.
//
// Gravity hoses: their counts and statuses are compared exactly, their figures are only
// measured (largestGravity). The gravity step's damped rounds branch on thresholds (a round is
// undone when its projection leaves more than it found, a point within 1e-9 of a collider is in
// contact), and a last-bit difference can take the other branch: on rig-options' valve-tail
// (gravity over two colliders) the two builds part by 1e-5 m after one step, and further after
// a grab out of reach.
export const TOLERANCE = 1e-9;
export const VERTEX_TOLERANCE = 1e-6;
export const SUM_TOLERANCE = 1e-5;
// The axial stiffness (EA, N per unit strain) capi_reference writes the pulls' forces for.
export const PULL_STIFFNESS = 1e4;

/**
 * api: the chaintube.mjs module; chaintube: a loaded ChainTube; bytes: the export (.glb);
 * name: its file name; referenceText: capi_reference's file. Returns { compared, largest
 * (the largest difference of a figure compared to TOLERANCE), failures: [text] }.
 */
export function replayReference(api, chaintube, bytes, name, referenceText) {
  const failures = [];
  let compared = 0, largest = 0, largestGravity = 0;
  const fail = (line, what) => failures.push(`reference line ${line}: ${what}`);
  let gravityHose = false; // the figures being compared are a gravity hose's
  function near(actual, expected, line, what, tolerance = TOLERANCE) {
    ++compared;
    const difference = Math.abs(actual - expected);
    if (gravityHose) {
      if (!Number.isFinite(actual)) fail(line, `${what}: WebAssembly ${actual}, native ${expected}`);
      largestGravity = Math.max(largestGravity, difference);
      return;
    }
    if (tolerance === TOLERANCE) largest = Math.max(largest, difference);
    if (!(difference <= tolerance)) fail(line, `${what}: WebAssembly ${actual}, native ${expected}`);
  }
  function same(actual, expected, line, what) {
    ++compared;
    if (actual !== expected) fail(line, `${what}: WebAssembly ${actual}, native ${expected}`);
  }
  function compareResult(result, v, line) {
    same(result.status, v[0], line, 'status');
    same(result.blocked ? 1 : 0, v[1], line, 'blocked');
    same(result.movedPoints, v[2], line, 'moved points');
    same(result.contacts, v[3], line, 'contacts');
    near(result.lengthViolation, v[4], line, 'length violation');
    near(result.angleViolation, v[5], line, 'angle violation');
    near(result.grabError, v[6], line, 'grab error');
    near(result.penetration, v[7], line, 'penetration');
  }

  const rig = chaintube.loadMemory(name, bytes);
  const fresh = chaintube.loadMemory(name, bytes);
  bytes.fill(0); // each rig keeps its own copy
  let grabResult = null, grabbedHose = -1, reelResult = null, reeledHose = -1;
  let fetched = null; // copies of one hose's outputs after the last input
  function fetch(hose) {
    if (fetched?.hose === hose) return fetched;
    const f64 = rig.jointPosesF64(hose);
    const f32 = rig.jointPoses(hose);
    const surface = rig.surface(hose);
    fetched = {
      hose,
      local: Float64Array.from(f64.local), world: Float64Array.from(f64.world),
      localF: Float32Array.from(f32.local), worldF: Float32Array.from(f32.world),
      nodes: rig.jointNodes(hose),
      positions: Float32Array.from(surface.positions), normals: Float32Array.from(surface.normals),
      topology: rig.surfaceTopology(hose),
    };
    return fetched;
  }

  referenceText.split('\n').forEach((text, index) => {
    const line = index + 1;
    if (!text.trim()) return;
    const words = text.split(' ');
    const v = words.slice(1).map(Number);
    const hose = words[0] === 'grab-result' ? grabbedHose : words[0] === 'reel-result' ? reeledHose
      : ['rig', 'node-name', 'socket'].includes(words[0]) ? -1 : v[0];
    gravityHose = hose >= 0 && hose < rig.hoseCount() && rig.hoseInfo(hose).hasGravity;
    try {
      switch (words[0]) {
        case 'rig':
          same(rig.hoseCount(), v[0], line, 'hose count');
          same(rig.nodeCount(), v[1], line, 'node count');
          break;
        case 'hose': {
          const info = rig.hoseInfo(v[0]);
          const id = words.slice(10).join(' ');
          same(info.pointCount, v[1], line, 'point count');
          same(info.jointCount, v[2], line, 'joint count');
          same(info.grabbableCount, v[3], line, 'grabbable count');
          same(info.vertexCount, v[4], line, 'vertex count');
          same(info.indexCount, v[5], line, 'index count');
          same(info.isStatic ? 1 : 0, v[6], line, 'static');
          near(info.restLength, v[7], line, 'rest length');
          near(info.outerRadius, v[8], line, 'outer radius');
          same(info.id, id, line, 'id');
          same(rig.findHose(id), v[0], line, 'findHose(id)');
          same(rig.grabbablePoints(v[0]).length, v[3], line, 'grabbablePoints length');
          break;
        }
        case 'node-name': {
          const nodeName = words.slice(2).join(' ');
          same(rig.findNode(nodeName), v[0], line, 'findNode(name)');
          same(rig.nodeInfo(v[0]).name, nodeName, line, 'node name');
          break;
        }
        case 'move': {
          const trs = v.slice(1, 11);
          fetched = null;
          rig.setNodeTransform(v[0], trs);
          rig.nodeTransform(v[0]).forEach((x, k) => near(x, trs[k], line, 'node transform read back'));
          break;
        }
        case 'grab':
          fetched = null;
          grabbedHose = v[0];
          grabResult = rig.grab(v[0], v[1], v.slice(2, 5));
          break;
        case 'grab-result':
          compareResult(grabResult, v, line);
          break;
        case 'reel':
          fetched = null;
          reeledHose = v[0];
          reelResult = rig.reel(v[0], v[1], v[3], v[4], v[5], v[2]);
          break;
        case 'reel-result':
          near(reelResult.paid, v[0], line, 'reel paid');
          near(reelResult.restLength, v[1], line, 'reel rest length');
          near(reelResult.largestMove, v[2], line, 'reel largest move');
          same(reelResult.clamped ? 1 : 0, v[3], line, 'reel clamped');
          same(reelResult.segmentsAdded, v[4], line, 'reel added');
          same(reelResult.segmentsRemoved, v[5], line, 'reel removed');
          same(reelResult.pointCount, v[6], line, 'reel points');
          same(rig.axisPoints(reeledHose).length, 3 * v[6], line, 'axis points');
          break;
        case 'release':
          fetched = null;
          rig.release(v[0]);
          break;
        case 'update':
          fetched = null;
          rig.update();
          break;
        case 'result':
          compareResult(rig.hoseResult(v[0]), v.slice(1), line);
          break;
        case 'pose': {
          const state = fetch(v[0]);
          const joint = v[1];
          same(state.nodes[joint], v[2], line, 'joint node');
          for (let k = 0; k < 10; ++k) {
            near(state.local[10 * joint + k], v[3 + k], line,
              k < 3 ? 'local translation' : k < 7 ? 'local rotation' : 'local scale');
            same(state.localF[10 * joint + k], Math.fround(state.local[10 * joint + k]), line,
              'float local pose vs the double one rounded');
          }
          for (let k = 0; k < 7; ++k) {
            near(state.world[7 * joint + k], v[13 + k], line, k < 3 ? 'world translation' : 'world rotation');
            same(state.worldF[7 * joint + k], Math.fround(state.world[7 * joint + k]), line,
              'float world pose vs the double one rounded');
          }
          break;
        }
        case 'surface': {
          const state = fetch(v[0]);
          same(state.positions.length / 3, v[1], line, 'vertex count');
          const sum = (array) => array.reduce((a, b) => a + b, 0);
          near(sum(state.positions), v[2], line, 'sum of surface positions', SUM_TOLERANCE);
          near(sum(state.normals), v[3], line, 'sum of surface normals', SUM_TOLERANCE);
          same(sum(state.topology.indices), v[4], line, 'sum of surface indices');
          near(sum(state.topology.uvs), v[5], line, 'sum of surface uvs', SUM_TOLERANCE);
          break;
        }
        case 'vertex': {
          const state = fetch(v[0]);
          for (let k = 0; k < 3; ++k) {
            near(state.positions[3 * v[1] + k], v[2 + k], line, 'surface position', VERTEX_TOLERANCE);
            near(state.normals[3 * v[1] + k], v[5 + k], line, 'surface normal', VERTEX_TOLERANCE);
          }
          break;
        }
        case 'attachments':
          same(rig.attachmentCount(v[0]), v[1], line, 'attachment count');
          break;
        case 'pull': {
          const pull = rig.attachmentPull(v[0], v[1], PULL_STIFFNESS);
          same(pull.node, v[2], line, 'attachment node');
          same(pull.firstPoint, v[3], line, 'attachment first point');
          same(pull.lastPoint, v[4], line, 'attachment last point');
          near(pull.tautness, v[5], line, 'tautness');
          near(pull.strain, v[6], line, 'strain');
          for (let k = 0; k < 3; ++k) {
            near(pull.direction[k], v[7 + k], line, 'pull direction');
            near(pull.force[k] / PULL_STIFFNESS, v[10 + k] / PULL_STIFFNESS, line, 'pull force / EA');
          }
          break;
        }
        case 'socket': {
          const socket = rig.socketInfo(v[0]);
          same(socket.node, v[1], line, 'socket node');
          same(socket.occupantHose, v[2], line, 'socket occupant hose');
          same(socket.occupantEnd, v[3], line, 'socket occupant end');
          same(socket.occupantAttachment, v[4], line, 'socket occupant attachment');
          for (let k = 0; k < 3; ++k) {
            near(socket.position[k], v[5 + k], line, 'socket position');
            near(socket.axis[k], v[8 + k], line, 'socket axis');
          }
          same(socket.id, words.slice(12).join(' '), line, 'socket id');
          same(rig.findSocket(socket.id), v[0], line, 'findSocket(id)');
          break;
        }
        case 'unplug':
          fetched = null;
          same(rig.unplug(v[0], v[1]), v[2], line, 'the socket unplugged from');
          break;
        case 'plug':
          fetched = null;
          same(rig.plug(v[0], v[1], v[2]), v[3], line, "the plug's attachment");
          break;
        case 'release-snap':
          fetched = null;
          same(rig.release(v[0]), v[1], line, 'the socket snapped into');
          break;
        default:
          fail(line, `unknown reference line "${words[0]}"`);
      }
    } catch (error) {
      fail(line, `${words[0]}: ${error.message}`);
    }
  });

  // The per-frame outputs are views of the module's memory, written in place: the same view
  // every frame (no allocation, no copy), showing the new poses after the next update. On a rig
  // as loaded (the replay may leave a hose's attachments pulled apart, and then it does not move).
  const deforming = [...Array(fresh.hoseCount()).keys()].find((h) => fresh.hoseInfo(h).grabbableCount > 0);
  const before = fresh.jointPoses(deforming).local;
  const beforeValues = Float32Array.from(before);
  const points = fresh.grabbablePoints(deforming);
  const world = fresh.jointPosesF64(deforming).world;
  const point = points[points.length >> 1];
  fresh.grab(deforming, point, [world[7 * point] + 0.05, world[7 * point + 1] + 0.05, world[7 * point + 2]]);
  fresh.update();
  const after = fresh.jointPoses(deforming).local;
  if (after !== before) fail(0, 'jointPoses returned a new array for the same hose: expected the same view');
  if (after.every((x, k) => x === beforeValues[k])) fail(0, 'the view did not change after a grab and an update');
  if (!(after.buffer.byteLength >= 16 << 20)) fail(0, 'the view is not a view of the module\'s memory');

  // Unplug, plug and cut through the JavaScript API on the fresh rig (the C and C# tests check
  // the figures; here each call's result and what it changes).
  {
    const attachments = fresh.attachmentCount(deforming);
    const count = fresh.hoseInfo(deforming).pointCount;
    // An attachment that holds an end: unplugged, then that end plugged 5 mm higher.
    const which = [...Array(attachments).keys()].find((a) => {
      const pull = fresh.attachmentPull(deforming, a);
      return pull.firstPoint === 0 || pull.lastPoint === count - 1;
    });
    if (which === undefined) fail(0, `hose ${deforming} has no attachment at an end`);
    else {
      const end = fresh.attachmentPull(deforming, which).firstPoint === 0 ? 0 : 1;
      fresh.release(deforming);
      fresh.detachEnd(deforming, which);
      if (fresh.attachmentPull(deforming, which).attached)
        fail(0, `detachEnd: attachment ${which} still attached`);
      if (fresh.grabbablePoints(deforming).length <= points.length)
        fail(0, 'detachEnd: the freed points did not become grabbable');
      fresh.update();
      const tip = Float64Array.from(fresh.jointPosesF64(deforming).world); // a copy: the view changes
      const at = end === 0 ? 0 : 7 * (count - 1), inner = end === 0 ? 7 : 7 * (count - 2);
      // The pose's +z along the end segment as it points now, out of the hose: the shortest turn
      // from +z, quaternion (z × d, 1 + z · d) normalised.
      const d = [0, 1, 2].map((k) => tip[at + k] - tip[inner + k]);
      const length = Math.hypot(...d);
      const q = [-d[1] / length, d[0] / length, 0, 1 + d[2] / length];
      const qLength = Math.hypot(...q);
      const plugged = fresh.attachEnd(deforming, end, -1,
        [tip[at], tip[at + 1] + 0.005, tip[at + 2], ...q.map((x) => x / qLength)]);
      if (plugged.attachment !== attachments || fresh.attachmentCount(deforming) !== attachments + 1)
        fail(0, `attachEnd: attachment ${plugged.attachment}, count ${fresh.attachmentCount(deforming)}`);
      fresh.update();
      // Under the real-time budget a plug the hose cannot follow in one update goes on in the next.
      for (let frame = 0; frame < 10 && fresh.hosePending(deforming).pending; ++frame) fresh.update();
      const moved = fresh.jointPosesF64(deforming).world;
      if (!(Math.abs(moved[at + 1] - (tip[at + 1] + 0.005)) <= 1e-9))
        fail(0, `attachEnd: the end is at y ${moved[at + 1]}, expected ${tip[at + 1] + 0.005}`);
    }
    const hoses = fresh.hoseCount();
    const piece = fresh.cut(deforming, count >> 1);
    if (piece !== hoses || fresh.hoseCount() !== hoses + 1 || fresh.jointNodes(piece)[0] !== -1)
      fail(0, `cut: new hose ${piece} of ${fresh.hoseCount()}, first joint node ${fresh.jointNodes(piece)[0]}`);
  }

  gravityHose = false;
  // Refusals: a ChainTubeError with the status and the C ABI's message; nothing changed.
  function expectError(what, status, fragment, call) {
    try {
      call();
      fail(0, `${what}: no error`);
    } catch (error) {
      if (!(error instanceof api.ChainTubeError)) fail(0, `${what}: ${error} is not a ChainTubeError`);
      else if (error.status !== status || !error.message.includes(fragment))
        fail(0, `${what}: status ${error.statusName} "${error.message}", expected status ${status} and "${fragment}"`);
    }
  }
  const hoses = rig.hoseCount();
  expectError('hose out of range', api.Status.ERROR_OUT_OF_RANGE, `hose ${hoses} is out of range`, () => rig.hoseInfo(hoses));
  expectError('NaN target', api.Status.ERROR_INVALID_ARGUMENT, 'chaintube_rig_grab', () => rig.grab(deforming, point, [NaN, 0, 0]));
  expectError('a target of 2 numbers', api.Status.ERROR_INVALID_ARGUMENT, 'target has 2 numbers', () => rig.grab(deforming, point, [0, 0]));
  expectError('a fractional index', api.Status.ERROR_INVALID_ARGUMENT, 'hose is 0.5', () => rig.release(0.5));
  expectError('attachment out of range', api.Status.ERROR_OUT_OF_RANGE, 'attachment 99 is out of range',
    () => rig.attachmentPull(deforming, 99, 1e4));
  expectError('negative axial stiffness', api.Status.ERROR_INVALID_ARGUMENT, 'axial_stiffness',
    () => rig.attachmentPull(deforming, 0, -1));
  expectError('a cut at an end', api.Status.ERROR_INVALID_ARGUMENT, 'expected an interior point',
    () => fresh.cut(deforming, 0));
  expectError('a plug of end 2', api.Status.ERROR_INVALID_ARGUMENT, 'end 2',
    () => fresh.attachEnd(deforming, 2, -1, [0, 0, 0, 0, 0, 0, 1]));
  expectError('unknown hose id', api.Status.ERROR_NOT_FOUND, 'no-such-hose', () => rig.findHose('no-such-hose'));
  // The work of a frame (ABI 1.3): refusals, then a hose's pending state, gone after an
  // unbounded update.
  expectError('a negative budget', api.Status.ERROR_INVALID_ARGUMENT, 'newton_steps', () => rig.setBudget(-1));
  expectError('pending of a hose out of range', api.Status.ERROR_OUT_OF_RANGE, `hose ${hoses} is out of range`,
    () => rig.hosePending(hoses));
  {
    const state = rig.hosePending(deforming);
    if (typeof state.pending !== 'boolean' || !(state.remaining >= 0) || (!state.pending && state.remaining !== 0))
      fail(0, `hosePending: ${JSON.stringify(state)}`);
    rig.setBudget(0);
    rig.update();
    const after = rig.hosePending(deforming);
    if (after.pending || after.remaining !== 0) fail(0, `hosePending after an unbounded update: ${JSON.stringify(after)}`);
  }
  // The frame's time (ABI 1.4): a bad time is refused naming `seconds`; an accepted one is
  // recorded with it.
  for (const seconds of [0, -0.01, 0.2, NaN, Infinity])
    expectError(`a frame of ${seconds} s`, api.Status.ERROR_INVALID_ARGUMENT, 'seconds', () => rig.update(seconds));
  {
    rig.recordInputs(true);
    rig.update(1 / 72);
    const recorded = rig.recordedInputs();
    rig.recordInputs(false);
    if (recorded.length !== 1 || recorded[0].op !== 'update' || recorded[0].seconds !== 1 / 72)
      fail(0, `update(1 / 72) recorded as ${JSON.stringify(recorded)}`);
  }
  expectError('not a GLB', api.Status.ERROR_MALFORMED, 'junk.glb',
    () => chaintube.loadMemory('junk.glb', new Uint8Array([0x67, 0x6c, 0x54, 0x46, 9, 0, 0, 0])));
  same(chaintube.abiVersion(), api.ABI_VERSION, 0, 'the module\'s ABI version');
  same(chaintube.statusName(api.Status.ERROR_BUFFER_TOO_SMALL), 'CHAINTUBE_ERROR_BUFFER_TOO_SMALL', 0, 'statusName');
  fresh.destroy();
  rig.destroy();
  rig.destroy(); // idempotent
  expectError('a destroyed rig', api.Status.ERROR_INVALID_ARGUMENT, 'destroyed', () => rig.hoseCount());
  return { compared, largest, largestGravity, failures };
}
