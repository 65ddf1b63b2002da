// ChainTube runtime for the web: the C ABI of chaintube/runtime_c.h compiled to WebAssembly
// (chaintube_runtime.wasm), behind a JavaScript API that mirrors it call for call. Guide and
// example: exporters/README.md, "The browser (WebAssembly)".
//
// Conventions, as in the C header: metres and radians; glTF's frames (right-handed, +Y up);
// quaternions x, y, z, w; a transform (TRS) is 10 numbers (translation, rotation, scale) relative
// to the node's parent, a rigid world pose 7 (translation, rotation). Indices are 0-based.
// A call that fails throws a ChainTubeError (status, the library's message) and changes nothing.
//
// Per-frame outputs (jointPoses, surface) are typed-array views of the module's memory that the
// C function has just written: no copy is made. A view is valid until the next call on the rig
// (the module's memory may grow and move, which empties old views): take it again each frame.
// A rig lives in the module's memory until destroy() is called; JavaScript's garbage collector
// does not free it.
import createChainTubeRuntime from './chaintube_runtime.mjs';

/** CHAINTUBE_RUNTIME_ABI_VERSION of the header this API was written against (major << 16 | minor). */
export const ABI_VERSION = (1 << 16) | 4;

/** chaintube_status: what a call returned. */
export const Status = Object.freeze({
  OK: 0,
  ERROR_INVALID_ARGUMENT: 1, // a missing or non-finite number, a zero scale or quaternion
  ERROR_OUT_OF_RANGE: 2, // a hose, node, point or warning index
  ERROR_BUFFER_TOO_SMALL: 3,
  ERROR_NOT_FOUND: 4, // findHose/findNode: no such name
  ERROR_NOT_GRABBABLE: 5, // a point fixed by an attachment, or a static hose
  ERROR_ABI_MISMATCH: 6,
  ERROR_UNREADABLE_FILE: 7,
  ERROR_MALFORMED: 8, // glTF, GLB or descriptor malformed or inconsistent
  ERROR_OUT_OF_MEMORY: 9,
  ERROR_INTERNAL: 10,
});

/** chaintube_hose_status: a hose's state after an update (HoseResult.status). */
export const HoseStatus = Object.freeze({
  OK: 0, // every request met, every constraint holds
  CLAMPED: 1, // a grab target was out of reach; every constraint holds
  INFEASIBLE: 2, // attachments contradict each other; violations reported
});

/** A refused call: `status` (a Status value), `statusName` ("CHAINTUBE_ERROR_…") and the
 * library's message naming the function, the argument or the file and field. */
export class ChainTubeError extends Error {
  constructor(status, statusName, message) {
    super(message);
    this.name = 'ChainTubeError';
    this.status = status;
    this.statusName = statusName;
  }
}

/**
 * Instantiates the WebAssembly module and returns the runtime's entry point, a ChainTube.
 * options go to emscripten's module factory: e.g. { wasmBinary } (the .wasm bytes, for Node or
 * a bundler) or { locateFile(name, prefix) } (where chaintube_runtime.wasm is served; by default
 * beside chaintube_runtime.mjs).
 */
export async function loadChainTube(options = {}) {
  return new ChainTube(await createChainTubeRuntime(options));
}

const textEncoder = new TextEncoder();
const textDecoder = new TextDecoder();
// Room for the small inputs and outputs of one call: a TRS, a target, an int32, a struct.
const SCRATCH_BYTES = 512;
const SCRATCH_OUTPUT = 256; // byte offset of the outputs within the scratch block

function bytesOf(what, value) {
  if (typeof value === 'string') return textEncoder.encode(value);
  if (value instanceof ArrayBuffer) return new Uint8Array(value);
  if (ArrayBuffer.isView(value)) return new Uint8Array(value.buffer, value.byteOffset, value.byteLength);
  throw new ChainTubeError(Status.ERROR_INVALID_ARGUMENT, 'CHAINTUBE_ERROR_INVALID_ARGUMENT',
    `${what}: expected an ArrayBuffer, a typed array or a string`);
}

// The module, its heap, a scratch block and the error check, shared by ChainTube and its rigs.
class Native {
  constructor(module) {
    this.m = module;
    this.scratch = module._malloc(SCRATCH_BYTES);
    this.layout = JSON.parse(this.string(module._chaintube_wasm_struct_layout()));
  }

  get u8() { return this.m.HEAPU8; }
  get i32() { return this.m.HEAP32; }
  get f64() { return this.m.HEAPF64; }

  string(pointer) {
    if (!pointer) return '';
    const heap = this.u8;
    let end = pointer;
    while (heap[end] !== 0) ++end;
    return textDecoder.decode(heap.subarray(pointer, end));
  }

  /** Copies bytes (plus a terminating 0 when cString) into a new block; free() it. */
  allocate(bytes, cString = false) {
    const pointer = this.m._malloc(bytes.length + (cString ? 1 : 0) || 1);
    if (!pointer) this.fail(Status.ERROR_OUT_OF_MEMORY, 'out of memory in the module');
    this.u8.set(bytes, pointer);
    if (cString) this.u8[pointer + bytes.length] = 0;
    return pointer;
  }

  free(pointer) { if (pointer) this.m._free(pointer); }

  fail(status, message) {
    throw new ChainTubeError(status, this.string(this.m._chaintube_status_name(status)), message);
  }

  check(status) {
    if (status !== Status.OK) this.fail(status, this.string(this.m._chaintube_last_error()));
  }

  int32(what, value) {
    if (!Number.isInteger(value) || value < -0x80000000 || value > 0x7fffffff)
      this.fail(Status.ERROR_INVALID_ARGUMENT, `${what} is ${value}: expected an integer`);
    return value;
  }

  /** Writes `count` numbers of an array-like to the scratch block as doubles; their address. */
  doubles(what, values, count) {
    if (values == null || values.length !== count)
      this.fail(Status.ERROR_INVALID_ARGUMENT,
        `${what} has ${values == null ? 'no' : values.length} numbers: expected ${count}`);
    const base = this.scratch >> 3;
    const heap = this.f64;
    for (let k = 0; k < count; ++k) heap[base + k] = values[k];
    return this.scratch;
  }

  get output() { return this.scratch + SCRATCH_OUTPUT; }
  outputInt32() { return this.i32[this.output >> 2]; }

  readStruct(kind, pointer, fields) {
    const offsets = this.layout[kind];
    const result = {};
    for (const [name, member, type] of fields) {
      const address = pointer + offsets[member];
      if (type === 'f64') result[name] = this.f64[address >> 3];
      else if (type === 'f64x3') result[name] = Array.from(this.f64.subarray(address >> 3, (address >> 3) + 3));
      else if (type === 'string') result[name] = this.string(this.m.HEAPU32[address >> 2]);
      else if (type === 'bool') result[name] = this.i32[address >> 2] !== 0;
      else result[name] = this.i32[address >> 2];
    }
    return result;
  }

  hoseResult(pointer) {
    return this.readStruct('hose_result', pointer, HOSE_RESULT_FIELDS);
  }
}

const HOSE_INFO_FIELDS = [
  ['id', 'id', 'string'], ['name', 'name', 'string'],
  ['restLength', 'rest_length', 'f64'], ['outerRadius', 'outer_radius', 'f64'],
  ['pointCount', 'point_count', 'i32'], ['jointCount', 'joint_count', 'i32'],
  ['grabbableCount', 'grabbable_count', 'i32'], ['vertexCount', 'vertex_count', 'i32'],
  ['indexCount', 'index_count', 'i32'], ['meshNode', 'mesh_node', 'i32'], ['skin', 'skin', 'i32'],
  ['isStatic', 'is_static', 'bool'], ['hasGravity', 'has_gravity', 'bool'],
  ['hasTorsion', 'has_torsion', 'bool'],
];
const HOSE_RESULT_FIELDS = [
  ['status', 'status', 'i32'], ['blocked', 'blocked', 'bool'],
  ['lengthViolation', 'length_violation', 'f64'], ['angleViolation', 'angle_violation', 'f64'],
  ['grabError', 'grab_error', 'f64'], ['penetration', 'penetration', 'f64'],
  ['movedPoints', 'moved_points', 'i32'], ['contacts', 'contacts', 'i32'],
];

const CLIP_INFO_FIELDS = [
  ['centre', 'centre', 'f64x3'], ['axis', 'axis', 'f64x3'], ['slide', 'slide', 'f64'],
  ['slideMin', 'slide_min', 'f64'], ['slideMax', 'slide_max', 'f64'], ['gap', 'gap', 'f64'],
  ['node', 'node', 'i32'], ['segment', 'segment', 'i32'], ['turning', 'turning', 'bool'],
];

const SOCKET_INFO_FIELDS = [
  ['id', 'id', 'string'], ['tag', 'tag', 'string'], ['position', 'position', 'f64x3'],
  ['axis', 'axis', 'f64x3'], ['captureRadius', 'capture_radius', 'f64'],
  ['captureAngle', 'capture_angle', 'f64'], ['node', 'node', 'i32'],
  ['occupantHose', 'occupant_hose', 'i32'], ['occupantEnd', 'occupant_end', 'i32'],
  ['occupantAttachment', 'occupant_attachment', 'i32'],
];

const REEL_RESULT_FIELDS = [
  ['paid', 'paid', 'f64'], ['restLength', 'rest_length', 'f64'],
  ['largestMove', 'largest_move', 'f64'], ['message', 'message', 'string'],
  ['clamped', 'clamped', 'bool'], ['segmentsAdded', 'segments_added', 'i32'],
  ['segmentsRemoved', 'segments_removed', 'i32'], ['pointCount', 'point_count', 'i32'],
];

const ATTACHMENT_PULL_FIELDS = [
  ['direction', 'direction', 'f64x3'], ['tautness', 'tautness', 'f64'], ['strain', 'strain', 'f64'],
  ['force', 'force', 'f64x3'], ['node', 'node', 'i32'], ['firstPoint', 'first_point', 'i32'],
  ['lastPoint', 'last_point', 'i32'], ['attached', 'attached', 'bool'],
];

/** The runtime: version, status names, the last error and loading rigs. */
export class ChainTube {
  #native;

  constructor(module) { this.#native = new Native(module); }

  /** The module's ABI version (chaintube_runtime_abi_version). */
  abiVersion() { return this.#native.m._chaintube_runtime_abi_version() >>> 0; }

  /** "CHAINTUBE_ERROR_BUFFER_TOO_SMALL" for a Status value (chaintube_status_name). */
  statusName(status) { return this.#native.string(this.#native.m._chaintube_status_name(status)); }

  /** What the last failing call got wrong, "" if none failed yet (chaintube_last_error). */
  lastError() { return this.#native.string(this.#native.m._chaintube_last_error()); }

  /**
   * Loads a rig from memory (chaintube_rig_load_memory): gltf is the .glb's bytes or a .gltf's
   * JSON text (ArrayBuffer, typed array or string); buffers[i] the bytes of the glTF's buffer i
   * when it has a uri (only collider meshes are read; an entry for a GLB's own buffer may be
   * null); sidecar the <name>.hoses.json text, used only when the glTF has no CHAINTUBE_hose_rig
   * extension. name names the export in messages ("rig.glb"). Everything is copied.
   */
  loadMemory(name, gltf, { buffers = [], sidecar = null } = {}) {
    const n = this.#native;
    const blocks = [];
    try {
      const gltfBytes = bytesOf('gltf', gltf);
      const gltfPointer = n.allocate(gltfBytes);
      blocks.push(gltfPointer);
      const namePointer = n.allocate(textEncoder.encode(name ?? '<memory>'), true);
      blocks.push(namePointer);
      const entry = n.layout.bytes;
      let buffersPointer = 0;
      if (buffers.length > 0) {
        buffersPointer = n.allocate(new Uint8Array(entry.sizeof * buffers.length));
        blocks.push(buffersPointer);
        buffers.forEach((buffer, i) => {
          if (buffer == null) return;
          const bytes = bytesOf(`buffers[${i}]`, buffer);
          const pointer = n.allocate(bytes);
          blocks.push(pointer);
          n.m.HEAPU32[(buffersPointer + i * entry.sizeof + entry.data) >> 2] = pointer;
          n.m.HEAPU32[(buffersPointer + i * entry.sizeof + entry.size) >> 2] = bytes.length;
        });
      }
      let sidecarPointer = 0, sidecarSize = 0;
      if (sidecar != null) {
        const bytes = bytesOf('sidecar', sidecar);
        sidecarPointer = n.allocate(bytes);
        sidecarSize = bytes.length;
        blocks.push(sidecarPointer);
      }
      n.check(n.m._chaintube_rig_load_memory(ABI_VERSION, namePointer, gltfPointer,
        gltfBytes.length, buffersPointer, buffers.length, sidecarPointer, sidecarSize, n.output));
      return new Rig(n, n.m.HEAPU32[n.output >> 2]);
    } finally {
      blocks.forEach((pointer) => n.free(pointer));
    }
  }
}

/** A loaded rig (chaintube_rig): the C functions chaintube_rig_* as methods. */
export class Rig {
  #native;
  #handle;
  #hoses = new Map(); // hose -> its output blocks in the module's memory and their views
  #inputs = null; // the recorded inputs while recordInputs(true)

  constructor(native, handle) {
    this.#native = native;
    this.#handle = handle;
  }

  #rig() {
    if (!this.#handle)
      this.#native.fail(Status.ERROR_INVALID_ARGUMENT, 'the rig was destroyed');
    return this.#handle;
  }

  /** Frees the rig and the blocks its views look at (chaintube_rig_destroy). Idempotent. */
  destroy() {
    if (!this.#handle) return;
    this.#native.m._chaintube_rig_destroy(this.#handle);
    this.#handle = 0;
    for (const outputs of this.#hoses.values())
      for (const block of Object.values(outputs.blocks)) this.#native.free(block.pointer);
    this.#hoses.clear();
  }

  /** The load report's warnings, as strings. */
  warnings() {
    const n = this.#native, rig = this.#rig();
    n.check(n.m._chaintube_rig_warning_count(rig, n.output));
    const texts = [];
    for (let i = 0, count = n.outputInt32(); i < count; ++i) {
      n.check(n.m._chaintube_rig_warning(rig, i, n.output));
      texts.push(n.string(n.m.HEAPU32[n.output >> 2]));
    }
    return texts;
  }

  hoseCount() { return this.#count('_chaintube_rig_hose_count'); }
  nodeCount() { return this.#count('_chaintube_rig_node_count'); }

  #count(fn) {
    const n = this.#native;
    n.check(n.m[fn](this.#rig(), n.output));
    return n.outputInt32();
  }

  /** Index of the hose with descriptor id `id` (throws ERROR_NOT_FOUND when there is none). */
  findHose(id) { return this.#find('_chaintube_rig_find_hose', id); }
  /** Index of the first node named `name` (throws ERROR_NOT_FOUND when there is none). */
  findNode(name) { return this.#find('_chaintube_rig_find_node', name); }

  #find(fn, text) {
    const n = this.#native, rig = this.#rig();
    const pointer = n.allocate(textEncoder.encode(String(text)), true);
    try {
      n.check(n.m[fn](rig, pointer, n.output));
    } finally {
      n.free(pointer);
    }
    return n.outputInt32();
  }

  /** A hose's properties: { id, name, restLength, outerRadius (metres), pointCount, jointCount,
   * grabbableCount, vertexCount, indexCount, meshNode, skin, isStatic, hasGravity, hasTorsion }. */
  hoseInfo(hose) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_hose_info(this.#rig(), n.int32('hose', hose), n.output));
    return n.readStruct('hose_info', n.output, HOSE_INFO_FIELDS);
  }

  /** The axis points grab() accepts, ascending (an Int32Array of its own): every point no
   * attachment fixes; a point a clip holds now (clipInfo's segment) is refused while it does. */
  grabbablePoints(hose) {
    const info = this.hoseInfo(hose);
    return this.#int32s('_chaintube_rig_grabbable_points', hose, info.grabbableCount);
  }

  /** The glTF node of each joint, in axis order (an Int32Array of its own; empty when static). */
  jointNodes(hose) {
    const info = this.hoseInfo(hose);
    return this.#int32s('_chaintube_rig_joint_nodes', hose, info.jointCount);
  }

  #int32s(fn, hose, count) {
    const n = this.#native;
    const pointer = n.allocate(new Uint8Array(4 * count));
    try {
      n.check(n.m[fn](this.#rig(), hose, pointer, count));
      return n.i32.slice(pointer >> 2, (pointer >> 2) + count);
    } finally {
      n.free(pointer);
    }
  }

  /** A hose's rest lengths and stretch band (chaintube_rig_rest_lengths): { restLengths (a
   * Float64Array of its own, metres, segment i between points i and i + 1), expansionCoefficient
   * (e: each segment stays within rest (1 - e) ... rest (1 + e)) }. */
  restLengths(hose) {
    const n = this.#native, rig = this.#rig();
    const count = this.hoseInfo(hose).pointCount - 1;
    const pointer = n.allocate(new Uint8Array(8 * count));
    try {
      n.check(n.m._chaintube_rig_rest_lengths(rig, hose, pointer, count, n.output));
      return {
        restLengths: n.f64.slice(pointer >> 3, (pointer >> 3) + count),
        expansionCoefficient: n.f64[n.output >> 3],
      };
    } finally {
      n.free(pointer);
    }
  }

  /** Number of clips of a hose (chaintube_rig_clip_count). */
  clipCount(hose) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_clip_count(this.#rig(), n.int32('hose', hose), n.output));
    return n.outputInt32();
  }

  /** Clip `clip` of a hose as the hose holds it now (chaintube_rig_clip_info): { centre [x, y, z]
   * (world metres), axis [x, y, z] (world, unit), slide (metres of rest length from point 0 to
   * the centre), slideMin, slideMax (its end stops), gap (metres, 0 while met), node (-1: the
   * world), segment (points segment and segment + 1 are held), turning }. */
  clipInfo(hose, clip) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_clip_info(this.#rig(), n.int32('hose', hose), n.int32('clip', clip),
      n.output));
    return n.readStruct('clip_info', n.output, CLIP_INFO_FIELDS);
  }

  /** Number of attachments of a hose (chaintube_rig_attachment_count; clips are not among them). */
  attachmentCount(hose) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_attachment_count(this.#rig(), n.int32('hose', hose), n.output));
    return n.outputInt32();
  }

  /** How hard a hose pulls on its attachment `attachment` after the last update()
   * (chaintube_rig_attachment_pull): { direction [x, y, z] (world, unit; zeros when slack),
   * tautness (0 slack ... 1 drawn straight), strain (>= 0), force [x, y, z] (world newtons for
   * axialStiffness, the hose's EA in newtons per unit strain: the platform states it), node (-1:
   * the world), firstPoint, lastPoint }. */
  attachmentPull(hose, attachment, axialStiffness = 0) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_attachment_pull(this.#rig(), n.int32('hose', hose),
      n.int32('attachment', attachment), Number(axialStiffness), n.output));
    return n.readStruct('attachment_pull', n.output, ATTACHMENT_PULL_FIELDS);
  }

  /** A node's { name, parent } (parent -1 at the scene root). */
  nodeInfo(node) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_node_info(this.#rig(), n.int32('node', node), n.output));
    return n.readStruct('node_info', n.output, [['name', 'name', 'string'], ['parent', 'parent', 'i32']]);
  }

  /** A node's current local transform: a Float64Array(10) of its own (TRS). */
  nodeTransform(node) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_node_transform(this.#rig(), n.int32('node', node), n.output));
    return n.f64.slice(n.output >> 3, (n.output >> 3) + 10);
  }

  /** A scene object moved: its local transform trs (10 numbers, relative to its parent); the
   * attachments and colliders on it and under it move, the hoses follow at the next update(). */
  setNodeTransform(node, trs) {
    const n = this.#native, rig = this.#rig();
    n.int32('node', node);
    n.check(n.m._chaintube_rig_set_node_transform(rig, node, n.doubles('trs', trs, 10)));
    this.#inputs?.push({ op: 'move', node, trs: Array.from(trs, Number) });
  }

  /** Moves axis point `point` of a hose to target [x, y, z] (world metres) and holds it there
   * until release() or a grab of another point. Returns this grab's outcome, a HoseResult:
   * { status (HoseStatus), blocked, lengthViolation, angleViolation (radians), grabError,
   * penetration (metres), movedPoints, contacts }. An unreachable target is not an error. */
  grab(hose, point, target) {
    const n = this.#native, rig = this.#rig();
    n.int32('hose', hose);
    n.int32('point', point);
    n.check(n.m._chaintube_rig_grab(rig, hose, point, n.doubles('target', target, 3), n.output));
    this.#inputs?.push({ op: 'grab', hose, point, target: Array.from(target, Number) });
    return n.hoseResult(n.output);
  }

  /** Unplugs an end: lets go of attachment `attachment` of a hose (chaintube_rig_detach_end): its
   * points fall free (with gravity from the next update()) and become grabbable; it keeps its
   * index, attached false. Returns this call's outcome, a HoseResult. */
  detachEnd(hose, attachment) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_detach_end(this.#rig(), n.int32('hose', hose),
      n.int32('attachment', attachment), n.output));
    return n.hoseResult(n.output);
  }

  /** Plugs end `end` of a hose (0: the first point's, 1: the last point's) into `node` (-1: the
   * world) at pose [tx, ty, tz, qx, qy, qz, qw], relative to the node; the end segment lies along
   * the pose's +z (chaintube_rig_attach_end). Returns { attachment (its index), result (a
   * HoseResult) }. */
  attachEnd(hose, end, node, pose) {
    const n = this.#native;
    n.int32('hose', hose);
    n.int32('end', end);
    n.int32('node', node);
    const result = n.output, index = n.output + 128;
    n.check(n.m._chaintube_rig_attach_end(this.#rig(), hose, end, node, n.doubles('pose', pose, 7),
      index, result));
    return { attachment: n.i32[index >> 2], result: n.hoseResult(result) };
  }

  /** Cuts a hose in two at axis point `point` (1 ... pointCount - 2; chaintube_rig_cut): the
   * hose keeps points 0 ... point, the returned new hose index gets the rest; the skin stays the
   * same, the new hose poses the joints beyond the cut (its jointNodes() start with -1). */
  cut(hose, point) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_cut(this.#rig(), n.int32('hose', hose), n.int32('point', point),
      n.output));
    return n.outputInt32();
  }

  /** Pays out (length > 0, metres) or reels in (length < 0) a hose where it leaves a reel
   * (chaintube_rig_reel): with clip -1 the outlet is the attachment fixing end `end` (0: the
   * first point's, 1: the last point's), with clip >= 0 that clip, the drum towards `end`. The
   * rest length stays within [minLength, maxLength]. A frame's call: speed × frame time. Returns
   * { paid (metres), restLength, largestMove, message ('' when all was paid), clamped,
   * segmentsAdded, segmentsRemoved, pointCount }. */
  reel(hose, end, length, minLength = 0, maxLength = Infinity, clip = -1) {
    const n = this.#native, rig = this.#rig();
    n.int32('hose', hose);
    n.int32('end', end);
    n.int32('clip', clip);
    n.check(n.m._chaintube_rig_reel(rig, hose, end, clip, Number(length), Number(minLength),
      Number(maxLength), n.output));
    const outputs = this.#hoses.get(hose);
    if (outputs) outputs.reeled = true; // the next update() may change its vertex count
    this.#inputs?.push({ op: 'reel', hose, end, clip, length: Number(length),
      min: Number(minLength), max: Number.isFinite(Number(maxLength)) ? Number(maxLength) : null });
    return n.readStruct('reel_result', n.output, REEL_RESULT_FIELDS);
  }

  /** A hose's axis points now (chaintube_rig_axis_points): a Float64Array of its own, 3 world
   * metres a point; the points grab() and cut() name (after a reel() no longer the joints'
   * positions). */
  axisPoints(hose) {
    const n = this.#native, rig = this.#rig();
    n.int32('hose', hose);
    const count = 3 * this.hoseInfo(hose).pointCount;
    const pointer = n.m._malloc(8 * count);
    try {
      n.check(n.m._chaintube_rig_axis_points(rig, hose, pointer, count));
      return n.m.HEAPF64.slice(pointer >> 3, (pointer >> 3) + count);
    } finally {
      n.m._free(pointer);
    }
  }

  /** Lets go of the hose's held point. A held end released in a free socket's capture whose tag
   * fits snaps in (chaintube_rig_release_snap): returns that socket's index, -1 when none caught
   * it. */
  release(hose) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_release_snap(this.#rig(), n.int32('hose', hose), n.output));
    this.#inputs?.push({ op: 'release', hose });
    return n.outputInt32();
  }

  // --- sockets (ABI 1.3) ---

  /** Number of sockets (chaintube_rig_socket_count). */
  socketCount() { return this.#count('_chaintube_rig_socket_count'); }
  /** Index of the socket with descriptor id `id` (throws ERROR_NOT_FOUND when there is none). */
  findSocket(id) { return this.#find('_chaintube_rig_find_socket', id); }

  /** Socket `socket` now (chaintube_rig_socket_info): { id, tag, position [x, y, z] (world
   * metres), axis [x, y, z] (world, unit, out of the part), captureRadius (metres), captureAngle
   * (radians), node (-1: the world), occupantHose (-1: free), occupantEnd, occupantAttachment }. */
  socketInfo(socket) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_socket_info(this.#rig(), n.int32('socket', socket), n.output));
    return n.readStruct('socket_info', n.output, SOCKET_INFO_FIELDS);
  }

  /** Plugs end `end` of a hose (0: the first point's, 1: the last point's) into socket `socket`
   * (chaintube_rig_plug): it eases in over the next updates, then follows the socket's part.
   * Returns the new attachment's index. Throws for a tag that does not fit, an occupied socket,
   * an end that is not free. */
  plug(hose, end, socket) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_plug(this.#rig(), n.int32('hose', hose), n.int32('end', end),
      n.int32('socket', socket), n.output));
    this.#inputs?.push({ op: 'plug', hose, end, socket });
    return n.outputInt32();
  }

  /** Unplugs end `end` of a hose (chaintube_rig_unplug): returns the socket it left (-1: an
   * attachment of the export). With gravity the end falls from the next update(). */
  unplug(hose, end) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_unplug(this.#rig(), n.int32('hose', hose), n.int32('end', end),
      n.output));
    this.#inputs?.push({ op: 'unplug', hose, end });
    return n.outputInt32();
  }

  /** Ends a frame: gravity steps, then the changed hoses' joint poses and surfaces. Returns how
   * many hoses changed. `seconds`: the frame's time in (0, 0.1] (a requestAnimationFrame delta,
   * clamped to 0.1), gravity advancing by it (ABI 1.4); omitted, a frame of 1/90 s. */
  update(seconds) {
    const n = this.#native;
    if (seconds === undefined) n.check(n.m._chaintube_rig_update(this.#rig(), n.output));
    else n.check(n.m._chaintube_rig_update_seconds(this.#rig(), Number(seconds), n.output));
    const recomputed = n.outputInt32();
    for (const [hose, outputs] of this.#hoses) // a reel's new vertex count shows from here
      if (outputs.reeled) {
        outputs.reeled = false;
        outputs.info = this.hoseInfo(hose);
      }
    this.#inputs?.push(seconds === undefined ? { op: 'update' } : { op: 'update', seconds: Number(seconds) });
    return recomputed;
  }

  /** What happened to a hose in the frame the last update() ended (a HoseResult, see grab). */
  hoseResult(hose) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_hose_result(this.#rig(), n.int32('hose', hose), n.output));
    return n.hoseResult(n.output);
  }

  /**
   * Bounds the Newton steps each node move, grab and update() does a hose (a rig loads with the
   * real-time budget, 16; 0 lifts the bound). What a frame cannot finish goes on in the next
   * update() calls: the hose is pending meanwhile (hosePending).
   */
  setBudget(newtonSteps) {
    const n = this.#native;
    n.check(n.m._chaintube_rig_set_budget(this.#rig(), n.int32('newtonSteps', newtonSteps)));
    this.#inputs?.push({ op: 'budget', newtonSteps });
  }

  /** { pending, remaining }: whether the hose's last update ran out of the budget and goes on in
   * the next update(), and how far it still is from its target (metres; 0 when not pending). */
  hosePending(hose) {
    const n = this.#native;
    const pending = n.output, remaining = n.output + 8;
    n.check(n.m._chaintube_rig_hose_pending(this.#rig(), n.int32('hose', hose), pending, remaining));
    return { pending: n.i32[pending >> 2] !== 0, remaining: n.f64[remaining >> 3] };
  }

  /**
   * Joint poses as of the last update, in axis order: { local, world } views (Float32Array)
   * of the module's memory. local: 10 numbers per joint, the TRS to write into the joint node
   * (relative to its glTF parent); world: 7 per joint, the rigid world pose (ring centre,
   * rotation). { local: false } or { world: false } skips one. Empty for a static hose.
   */
  jointPoses(hose, { local = true, world = true } = {}) {
    return this.#poses('_chaintube_rig_joint_poses', Float32Array, hose, local, world);
  }

  /** jointPoses in double precision (Float64Array views). */
  jointPosesF64(hose, { local = true, world = true } = {}) {
    return this.#poses('_chaintube_rig_joint_poses_f64', Float64Array, hose, local, world);
  }

  #poses(fn, Type, hose, wantLocal, wantWorld) {
    const n = this.#native, rig = this.#rig();
    const outputs = this.#outputs(hose);
    const count = outputs.info.jointCount;
    const suffix = Type === Float64Array ? '64' : '32';
    const local = wantLocal ? this.#block(outputs, 'local' + suffix, Type, 10 * count) : null;
    const world = wantWorld ? this.#block(outputs, 'world' + suffix, Type, 7 * count) : null;
    if (count > 0)
      n.check(n.m[fn](rig, hose, local?.pointer ?? 0, 10 * count, world?.pointer ?? 0, 7 * count));
    return { local: local ? this.#view(local) : null, world: world ? this.#view(world) : null };
  }

  /** The hose's surface as of the last update: { positions, normals } views (Float32Array,
   * 3 per vertex; positions in world metres). { normals: false } skips the normals. */
  surface(hose, { positions = true, normals = true } = {}) {
    const n = this.#native, rig = this.#rig();
    const outputs = this.#outputs(hose);
    const size = 3 * outputs.info.vertexCount;
    const p = positions ? this.#block(outputs, 'positions', Float32Array, size) : null;
    const q = normals ? this.#block(outputs, 'normals', Float32Array, size) : null;
    n.check(n.m._chaintube_rig_surface(rig, hose, p?.pointer ?? 0, size, q?.pointer ?? 0, size));
    return { positions: p ? this.#view(p) : null, normals: q ? this.#view(q) : null };
  }

  /** The surface's fixed parts, arrays of their own: { indices (Uint32Array, 3 per triangle,
   * counter-clockwise from outside), uvs (Float32Array, 2 per vertex) }. */
  surfaceTopology(hose) {
    const n = this.#native, rig = this.#rig();
    const info = this.hoseInfo(hose);
    const indices = n.allocate(new Uint8Array(4 * info.indexCount));
    const uvs = n.allocate(new Uint8Array(8 * info.vertexCount));
    try {
      n.check(n.m._chaintube_rig_surface_topology(rig, hose, indices, info.indexCount, uvs,
        2 * info.vertexCount));
      return {
        indices: n.m.HEAPU32.slice(indices >> 2, (indices >> 2) + info.indexCount),
        uvs: n.m.HEAPF32.slice(uvs >> 2, (uvs >> 2) + 2 * info.vertexCount),
      };
    } finally {
      n.free(indices);
      n.free(uvs);
    }
  }

  /**
   * Starts (true) or stops (false) recording this rig's inputs: every accepted setNodeTransform,
   * grab, release, plug, unplug, reel, update and setBudget, in order, as { op: 'move', node,
   * trs }, { op: 'grab', hose, point, target }, { op: 'release', hose }, { op: 'plug', hose, end,
   * socket }, { op: 'unplug', hose, end }, { op: 'reel', hose, end, clip, length, min, max },
   * { op: 'update' } or { op: 'update', seconds }, { op: 'budget', newtonSteps }. Starting clears the record. Replaying
   * it through the C ABI gives the same hoses (a bug report, or a check against a native build).
   */
  recordInputs(on) { this.#inputs = on ? [] : null; }

  /** The inputs recorded since recordInputs(true) (a copy), or null when not recording. */
  recordedInputs() { return this.#inputs ? this.#inputs.slice() : null; }

  #outputs(hose) {
    let outputs = this.#hoses.get(hose);
    if (!outputs) {
      outputs = { info: this.hoseInfo(hose), blocks: {}, reeled: false };
      this.#hoses.set(hose, outputs);
    } else if (outputs.reeled) { // reeled since the last update(): counts as they are now
      outputs.info = this.hoseInfo(hose);
    }
    return outputs;
  }

  // A block of `count` elements in the module's memory, allocated on first use, kept until
  // destroy(); its view is made again when the memory has grown.
  #block(outputs, key, Type, count) {
    let block = outputs.blocks[key];
    if (block && block.count !== count) { // a reel changed the hose's vertex count
      this.#native.free(block.pointer);
      block = null;
    }
    if (!block) {
      const pointer = this.#native.allocate(new Uint8Array(Type.BYTES_PER_ELEMENT * Math.max(count, 1)));
      block = outputs.blocks[key] = { pointer, Type, count, view: null };
    }
    return block;
  }

  #view(block) {
    const buffer = this.#native.u8.buffer;
    if (!block.view || block.view.buffer !== buffer)
      block.view = new block.Type(buffer, block.pointer, block.count);
    return block.view;
  }
}
