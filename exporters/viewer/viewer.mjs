// The ChainTube web viewer: opens an exported hose rig (.glb), shows it with three.js and runs
// its hoses with the runtime's WebAssembly build, loaded from the same bytes. Each frame: the
// parts moved with the gizmo go to the runtime (setNodeTransform), a hose point held by the
// mouse or a VR controller is grabbed, the runtime updates, and its joint poses are written
// into the skinned hoses' bones and each clip's ring is placed where the runtime holds it.
// Guide: exporters/README.md, "The web viewer".
//
// URL parameters: file=URL opens an export at start; runtime=URL is where chaintube.mjs is
// served (default: the WebAssembly build in build-wasm/chaintube/, seen from this folder);
// record=1 records the rig's inputs from the load on (window.chaintubeViewer.snapshot()).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';
import { VRButton } from 'three/addons/webxr/VRButton.js';

const params = new URLSearchParams(location.search);
const runtimeUrl = new URL(params.get('runtime') ?? '../../build-wasm/chaintube/chaintube.mjs',
  location.href).href;
const recordInputs = params.get('record') === '1';

const fileInput = document.getElementById('file-input');
const fileLabel = document.getElementById('file-name');
const hoseTable = document.querySelector('#hoses tbody');
const selectionLabel = document.getElementById('selection');
const messageBox = document.getElementById('message');
const dropOverlay = document.getElementById('drop-overlay');

// The state the automation hook reports (window.chaintubeViewer.state).
let viewerState = 'starting';
let lastMessage = '';

function showMessage(text) {
  lastMessage = text;
  messageBox.textContent = text;
  messageBox.hidden = false;
}

function hideMessage() {
  lastMessage = '';
  messageBox.hidden = true;
}

// --- three.js scene --------------------------------------------------------------------------
const renderer = new THREE.WebGLRenderer({ antialias: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.xr.enabled = true;
document.body.prepend(renderer.domElement);
document.body.appendChild(VRButton.createButton(renderer));

const scene = new THREE.Scene();
scene.background = new THREE.Color(0x2b2f36);
scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
sun.position.set(1, 2, 1.5);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(45, window.innerWidth / window.innerHeight, 0.01, 100);
camera.position.set(0.6, 0.5, 0.9);

// The rig's world: the runtime works in this group's frame (the glTF scene's root). On desktop
// it is the world; in VR it is placed in front of the viewer.
const rigRoot = new THREE.Group();
scene.add(rigRoot);

// The clips (guides a hose slides through) are not in the glTF: each is drawn as a ring around
// the hose, magenta as in the editor, red while the hose is off it (its gap above kClipMet).
const clipRings = new THREE.Group();
clipRings.name = 'clip rings';
rigRoot.add(clipRings);
const kClipMet = 1e-6; // metres
const clipMetColour = new THREE.Color(0xd23cd2);
const clipOffColour = new THREE.Color(0xe03030);

// Sockets (couplings a hose end plugs into) are not in the glTF either: each is drawn as a ring
// around its axis at its position, with a faint disc its capture radius wide; green while free,
// blue while it holds an end. A hose end dragged with its ray through a free socket's capture is
// guided in along the socket's axis from kGuideHeight above it, down to kGuideHeightMin; released
// there, the runtime snaps it in. U unplugs the selected hose end (the one nearest the last press
// on a hose).
const socketMarks = new THREE.Group();
socketMarks.name = 'sockets';
rigRoot.add(socketMarks);
const socketFreeColour = new THREE.Color(0x3cc878);
const socketHeldColour = new THREE.Color(0x3c8cf0);
const kGuideHeight = 0.2; // metres above the socket where a guided end starts
const kGuideHeightMin = 0.01; // metres: where it is held, within the capture radius
const kGuideStep = 0.02; // metres a frame
const kGuideBeyond = 0.06; // metres beyond the socket where the guide starts
const kEndReach = 3; // a press this many points from a free end takes the end point
let selectedEnd = null; // { hose (index), end (0 or 1) }

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

// The gizmo's listeners come first, the viewer's next, the orbit controls' last: a press on
// the gizmo or on a hose never starts an orbit.
const gizmo = new TransformControls(camera, renderer.domElement);
scene.add(gizmo.getHelper());
renderer.domElement.addEventListener('pointerdown', onPointerDown);
renderer.domElement.addEventListener('pointermove', onPointerMove);
renderer.domElement.addEventListener('pointerup', onPointerUp);
const orbit = new OrbitControls(camera, renderer.domElement);
orbit.enableDamping = false;
gizmo.addEventListener('dragging-changed', (event) => { orbit.enabled = !event.value; });
let gizmoPressed = false; // the press that ends in the next pointerup began on the gizmo
gizmo.addEventListener('mouseDown', () => { gizmoPressed = true; });
gizmo.addEventListener('objectChange', () => {
  if (current && selectedPart >= 0) current.movedParts.add(selectedPart);
});

// --- the runtime -----------------------------------------------------------------------------
let HoseStatus = null; // the API's enum, once loaded
const runtimePromise = import(runtimeUrl).then((api) => {
  HoseStatus = api.HoseStatus;
  return api.loadChainTube();
}).catch((error) => {
  throw new Error(`The ChainTube runtime (WebAssembly) could not be loaded from ${runtimeUrl}: ` +
    `${error.message ?? error}.\nBuild it with ./build.sh (it needs Debian's emscripten).`);
});

// The open rig: { name, rig, gltf, nodes (Object3D by glTF node index), hoses, parts (the
// nodes hoses are fixed to), movedParts, hoseOfMesh, frames }. A hose: { index, info,
// grabbable (Set), bones, clips (a ring Mesh per clip), clipHeld (Set of the points its clips
// hold now), row, shown, shownText }.
let current = null;
let selectedPart = -1; // glTF node under the gizmo
let drag = null; // { hose, point, target [x, y, z] rig metres, plane | controller + offset }

function isGlb(bytes) {
  return bytes.length >= 4 && bytes[0] === 0x67 && bytes[1] === 0x6c && bytes[2] === 0x54 &&
    bytes[3] === 0x46; // "glTF"
}

/** The glTF JSON of a .glb or .gltf, or null when it is neither. */
function gltfJson(bytes) {
  try {
    if (isGlb(bytes)) {
      const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      const length = view.getUint32(12, true);
      return JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + length)));
    }
    return JSON.parse(new TextDecoder().decode(bytes));
  } catch {
    return null;
  }
}

/**
 * Opens an export: name names it in messages; bytes are the .glb or .gltf; readResource(uri)
 * returns the bytes (Uint8Array) of a file beside it, or rejects. The runtime reads the bytes
 * first (its messages name what is wrong), then three.js. On failure the message says why and
 * the rig shown before stays.
 */
async function openRig(name, bytes, readResource) {
  viewerState = 'loading';
  hideMessage();
  fileLabel.textContent = `Opening ${name}…`;
  let rig = null;
  try {
    const chaintube = await runtimePromise;
    const json = gltfJson(bytes);
    const buffers = [];
    let sidecar = null;
    if (json && !isGlb(bytes)) {
      for (const buffer of json.buffers ?? [])
        buffers.push(buffer.uri && !buffer.uri.startsWith('data:')
          ? await readResource(buffer.uri).catch(() => null) : null);
    }
    if (json && !json.extensions?.CHAINTUBE_hose_rig)
      sidecar = await readResource(name.replace(/\.(glb|gltf)$/i, '') + '.hoses.json').catch(() => null);
    rig = chaintube.loadMemory(name, bytes, { buffers, sidecar });
    if (recordInputs) rig.recordInputs(true);
    const loader = new GLTFLoader(await resourceManager(json, readResource));
    let gltf;
    try {
      gltf = await loader.parseAsync(bytes.slice().buffer, '');
    } catch (error) {
      throw new Error(`${name}: three.js cannot read it: ${error.message ?? error}`);
    }
    show(name, rig, gltf);
    rig = null;
    viewerState = 'loaded';
  } catch (error) {
    rig?.destroy();
    viewerState = 'error';
    fileLabel.textContent = current ? current.name : 'No rig loaded';
    showMessage(`Could not open ${name}.\n\n${error.message ?? error}`);
  }
}

// The files a .gltf refers to, for three.js: each relative uri is read with readResource
// and handed over as an object URL.
async function resourceManager(json, readResource) {
  const manager = new THREE.LoadingManager();
  const urls = new Map();
  for (const item of [...(json?.buffers ?? []), ...(json?.images ?? [])]) {
    if (!item.uri || item.uri.startsWith('data:') || urls.has(item.uri)) continue;
    urls.set(item.uri, URL.createObjectURL(new Blob([await readResource(item.uri)])));
  }
  manager.setURLModifier((url) => urls.get(url) ?? url);
  return manager;
}

/** Replaces the shown rig with a loaded one. */
function show(name, rig, gltf) {
  if (current) {
    rigRoot.remove(current.gltf.scene);
    current.rig.destroy();
  }
  for (const ring of clipRings.children) {
    ring.geometry.dispose();
    ring.material.dispose();
  }
  clipRings.clear();
  for (const mark of socketMarks.children)
    mark.traverse((o) => { o.geometry?.dispose(); o.material?.dispose(); });
  socketMarks.clear();
  selectedEnd = null;
  gizmo.detach();
  selectedPart = -1;
  drag = null;
  const nodes = [];
  gltf.scene.traverse((object) => {
    const index = gltf.parser.associations.get(object)?.nodes;
    if (index !== undefined) nodes[index] = object;
  });
  const hoses = [];
  const hoseOfMesh = new Map();
  const parts = new Map(); // node -> the joints fixed to it: [{ hose (id), joint }]
  for (let h = 0, count = rig.hoseCount(); h < count; ++h) {
    const info = rig.hoseInfo(h);
    const jointNodes = rig.jointNodes(h);
    const grabbable = new Set(rig.grabbablePoints(h));
    const bones = Array.from(jointNodes, (node) => nodes[node]);
    const hose = { index: h, info, grabbable, bones, clips: [], clipHeld: new Set(), row: null, shown: null, shownText: '', tension: '' };
    for (let c = 0, clips = rig.clipCount(h); c < clips; ++c) {
      // A ring 1.6 hose radii wide (TorusGeometry turns about its z axis), drawn over the hose.
      const r = info.outerRadius;
      const ring = new THREE.Mesh(new THREE.TorusGeometry(1.6 * r, 0.3 * r, 12, 48),
        new THREE.MeshStandardMaterial({ color: clipMetColour, roughness: 0.5 }));
      ring.name = `${info.id} clip ${c}`;
      clipRings.add(ring);
      hose.clips.push(ring);
    }
    hoses.push(hose);
    nodes[info.meshNode]?.traverse((object) => {
      if (!object.isMesh) return;
      object.frustumCulled = false; // its bones move it far from the bounds it was loaded with
      if (!info.isStatic) hoseOfMesh.set(object, hose);
    });
    // The parts that hoses are fixed to: the parents of fixed joints other than the hose's own
    // joints node (the parent of its free joints), and the node carrying a static hose.
    const freeParents = new Set();
    jointNodes.forEach((node, j) => { if (grabbable.has(j)) freeParents.add(rig.nodeInfo(node).parent); });
    jointNodes.forEach((node, j) => {
      const parent = rig.nodeInfo(node).parent;
      if (grabbable.has(j) || parent < 0 || freeParents.has(parent)) return;
      if (!parts.has(parent)) parts.set(parent, []);
      parts.get(parent).push({ hose: info.id, joint: j });
    });
    if (info.isStatic) {
      const parent = rig.nodeInfo(info.meshNode).parent;
      if (parent >= 0 && !parts.has(parent)) parts.set(parent, []);
    }
  }
  rigRoot.add(gltf.scene);
  current = { name, rig, gltf, nodes, hoses, parts, movedParts: new Set(), hoseOfMesh, frames: 0, sockets: [] };
  for (const hose of hoses) placeClipRings(rig, hose);
  for (let k = 0, count = rig.socketCount(); k < count; ++k) {
    const socket = rig.socketInfo(k);
    const r = socket.captureRadius;
    const ring = new THREE.Mesh(new THREE.TorusGeometry(0.5 * r, 0.08 * r, 12, 48),
      new THREE.MeshStandardMaterial({ color: socketFreeColour, roughness: 0.5 }));
    const disc = new THREE.Mesh(new THREE.CircleGeometry(r, 48),
      new THREE.MeshBasicMaterial({ color: socketFreeColour, transparent: true, opacity: 0.25,
        side: THREE.DoubleSide, depthWrite: false }));
    ring.add(disc);
    ring.name = `socket ${socket.id}`;
    socketMarks.add(ring);
    current.sockets.push({ index: k, id: socket.id, ring, disc, info: socket });
  }
  placeSockets(rig);
  buildPanel();
  frameView(gltf.scene);
  fileLabel.textContent = name;
  for (const warning of rig.warnings()) console.warn(`${name}: ${warning}`);
}

function frameView(object) {
  const box = new THREE.Box3().setFromObject(object);
  if (box.isEmpty()) return;
  const centre = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 0.05);
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 0.9;
  camera.position.copy(centre).add(new THREE.Vector3(0.55, 0.45, 0.7).normalize().multiplyScalar(distance));
  camera.near = distance / 100;
  camera.far = distance * 100;
  camera.updateProjectionMatrix();
  orbit.target.copy(centre);
  orbit.update();
  gizmo.size = 0.8;
}

// --- the panel -------------------------------------------------------------------------------
function buildPanel() {
  hoseTable.replaceChildren();
  for (const hose of current.hoses) {
    const row = document.createElement('tr');
    row.dataset.hose = hose.info.id;
    const name = document.createElement('td');
    name.textContent = hose.info.name || hose.info.id;
    name.title = hose.info.id;
    row.append(name, document.createElement('td'), document.createElement('td'),
      document.createElement('td'));
    hoseTable.append(row);
    row.addEventListener('click', () => selectHose(hose.index));
    hose.row = row;
    hose.shown = null;
    hose.shownText = '';
    hose.tension = '';
    renderRow(hose);
  }
  selectionLabel.textContent = '';
}

// A frame's result counts when something touched the hose; the panel shows the last one, so a
// hose stays "clamped" or "infeasible" while nothing moves it.
function touched(result) {
  return result.movedPoints > 0 || result.status !== HoseStatus.OK || result.blocked ||
    result.lengthViolation > 0 || result.angleViolation > 0 || result.contacts > 0;
}

function statusWords(hose) {
  const r = hose.shown;
  if (hose.info.isStatic) return ['static', 'ok', ''];
  if (!r) return ['ok', 'ok', ''];
  const status = r.status === HoseStatus.CLAMPED ? 'clamped'
    : r.status === HoseStatus.INFEASIBLE ? 'infeasible' : 'ok';
  const flags = [];
  if (r.blocked) flags.push('blocked');
  if (r.lengthViolation > 1e-6) flags.push(`over-stretched ${(100 * r.lengthViolation).toFixed(1)} %`);
  if (r.angleViolation > 1e-6) flags.push(`over-bent ${THREE.MathUtils.radToDeg(r.angleViolation).toFixed(1)}°`);
  if (r.penetration > 1e-6) flags.push(`${(1000 * r.penetration).toFixed(1)} mm in a collider`);
  const css = r.status === HoseStatus.INFEASIBLE ? 'infeasible'
    : r.lengthViolation > 1e-6 ? 'over-stretched' : r.blocked ? 'blocked' : status;
  return [status, css, flags.join(', ')];
}

// Each attachment's tautness after the last update, 0 (slack) … 1 (drawn straight), in the
// descriptor's order ("–" for one unplugged): "0.00 0.97".
function tensionText(rig, hose) {
  const words = [];
  for (let a = 0; a < rig.attachmentCount(hose.index); ++a) {
    const pull = rig.attachmentPull(hose.index, a);
    words.push(pull.attached ? pull.tautness.toFixed(2) : '–');
  }
  return words.join(' ');
}

function renderRow(hose) {
  const [status, css, flags] = statusWords(hose);
  const held = drag?.hose === hose.index;
  const text = `${status}|${flags}|${held}|${hose.tension}`;
  if (text === hose.shownText) return;
  hose.shownText = text;
  const [, statusCell, flagsCell, tensionCell] = hose.row.children;
  tensionCell.textContent = hose.tension;
  tensionCell.title = 'tautness of each attachment: 0 slack … 1 drawn straight';
  statusCell.textContent = status;
  statusCell.className = `status-${css}`;
  flagsCell.textContent = flags;
  flagsCell.className = flags ? `status-${css}` : '';
  hose.row.classList.toggle('held', held);
}

// --- picking and dragging --------------------------------------------------------------------
const raycaster = new THREE.Raycaster();
let pressedAt = null; // { x, y } of a press that may become a click

function rayFromEvent(event) {
  const rect = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  return raycaster;
}

/** The first thing the ray hits: { hose, point (grabbable, nearest the hit), hit } for a hose
 * that deforms, { object, hit } for anything else, or null. */
function pick(caster) {
  if (!current) return null;
  for (const mesh of current.hoseOfMesh.keys()) mesh.computeBoundingSphere(); // posed bounds
  const hit = caster.intersectObject(current.gltf.scene, true)[0];
  if (!hit) return null;
  const hose = current.hoseOfMesh.get(hit.object);
  if (!hose) return { object: hit.object, hit };
  const world = current.rig.axisPoints(hose.index); // grab names axis points (a reel adds some)
  const p = rigRoot.worldToLocal(hit.point.clone());
  let best = -1, bestDistance = Infinity;
  for (const point of hose.grabbable) {
    if (hose.clipHeld.has(point)) continue; // a clip slid onto it: the runtime refuses its grab
    const d = Math.hypot(world[3 * point] - p.x, world[3 * point + 1] - p.y, world[3 * point + 2] - p.z);
    if (d < bestDistance) { bestDistance = d; best = point; }
  }
  // A press on a hose's last few segments near a free end takes the end itself (its end point
  // often sits inside the part it was plugged into): it is what a hand plugs into a socket.
  const last = hose.info.pointCount - 1;
  const distance = (point) => Math.hypot(world[3 * point] - p.x, world[3 * point + 1] - p.y, world[3 * point + 2] - p.z);
  let nearest = 0;
  for (let point = 1; point <= last; ++point) if (distance(point) < distance(nearest)) nearest = point;
  const end = distance(0) <= distance(last) ? 0 : 1;
  if (nearest <= kEndReach && hose.grabbable.has(0)) best = 0;
  else if (nearest >= last - kEndReach && hose.grabbable.has(last)) best = last;
  return best >= 0 ? { hose: hose.index, point: best, end, hit } : null;
}

function pointWorld(hose, point) {
  return rigRoot.localToWorld(new THREE.Vector3().fromArray(current.rig.axisPoints(hose), 3 * point));
}

function onPointerDown(event) {
  if (!current || event.button !== 0 || gizmo.dragging) return;
  pressedAt = { x: event.clientX, y: event.clientY };
  const picked = pick(rayFromEvent(event));
  if (!picked || picked.hose === undefined) return;
  selectHose(picked.hose);
  selectEnd(picked.hose, picked.end);
  const start = pointWorld(picked.hose, picked.point);
  const normal = camera.getWorldDirection(new THREE.Vector3());
  drag = {
    hose: picked.hose, point: picked.point, plane: new THREE.Plane().setFromNormalAndCoplanarPoint(normal, start),
    target: rigRoot.worldToLocal(start.clone()).toArray(),
  };
  orbit.enabled = false;
  renderer.domElement.setPointerCapture(event.pointerId);
  pressedAt = null;
}

function onPointerMove(event) {
  if (!drag || !drag.plane) return;
  const caster = rayFromEvent(event);
  guideToSocket(caster.ray);
  const target = caster.ray.intersectPlane(drag.plane, new THREE.Vector3());
  if (target) drag.target = rigRoot.worldToLocal(target).toArray();
}

/** A dragged hose end whose ray passes through a free socket's capture is guided into it (see
 * socketMarks); a ray away from every socket lets it go again. */
function guideToSocket(ray) {
  const last = current.hoses[drag.hose].info.pointCount - 1;
  if (drag.point !== 0 && drag.point !== last) return;
  rigRoot.updateMatrixWorld(true);
  let caught = null;
  for (const socket of current.sockets) {
    if (socket.info.occupantHose >= 0) continue;
    const at = rigRoot.localToWorld(new THREE.Vector3().fromArray(socket.info.position));
    if (ray.distanceToPoint(at) <= socket.info.captureRadius) caught = socket;
  }
  if (caught?.index === drag.guide?.socket) return;
  drag.guide = null;
  if (!caught) return;
  // It comes down from beyond the socket, seen from the hose's other end, so that the hose behind
  // it leans the end segment onto the axis (within the capture angle) rather than away.
  const axis = new THREE.Vector3().fromArray(caught.info.axis);
  const world = current.rig.axisPoints(drag.hose);
  const other = new THREE.Vector3().fromArray(world, drag.point === 0 ? 3 * last : 0);
  const beyond = new THREE.Vector3().fromArray(caught.info.position).sub(other);
  beyond.addScaledVector(axis, -beyond.dot(axis));
  drag.guide = { socket: caught.index, height: kGuideHeight,
    beyond: beyond.lengthSq() > 0 ? beyond.normalize().toArray() : [0, 0, 0] };
}

function onPointerUp(event) {
  if (drag && drag.plane) {
    endDrag();
    orbit.enabled = true;
    return;
  }
  const wasGizmo = gizmoPressed;
  gizmoPressed = false;
  const press = pressedAt;
  pressedAt = null;
  if (!current || wasGizmo || !press || event.button !== 0) return;
  if (Math.hypot(event.clientX - press.x, event.clientY - press.y) > 4) return; // an orbit
  const picked = pick(rayFromEvent(event));
  selectPart(picked && picked.object ? partOf(picked.object) : -1);
}

function endDrag() {
  if (!drag) return;
  const hose = current.hoses[drag.hose];
  const end = drag.point === 0 ? 0 : 1;
  let socket = current.rig.release(drag.hose);
  if (socket < 0 && drag.guide) {
    // Guided onto a socket but not caught (its segment off the capture angle): plug it there.
    try {
      current.rig.plug(hose.index, end, drag.guide.socket);
      socket = drag.guide.socket;
    } catch (error) {
      selectionLabel.textContent = error.message; // e.g. the socket takes another plug
    }
  }
  hose.grabbable = new Set(current.rig.grabbablePoints(hose.index));
  if (socket >= 0) selectionLabel.textContent = `${hose.info.id} end ${end} ` +
    `plugged into socket ${current.sockets[socket].id} (U unplugs it)`;
  if (hose.shown?.status === HoseStatus.CLAMPED) hose.shown = { ...hose.shown, status: HoseStatus.OK };
  drag = null;
  renderRow(hose);
}

/** The part a clicked object belongs to: the nearest node up from it that hoses are fixed to,
 * else the clicked object's own node. */
function partOf(object) {
  const associations = current.gltf.parser.associations;
  let own = -1;
  for (let o = object; o && o !== current.gltf.scene; o = o.parent) {
    const node = associations.get(o)?.nodes;
    if (node === undefined) continue;
    if (current.parts.has(node)) return node;
    if (own < 0) own = node;
  }
  return own;
}

function selectPart(node) {
  selectedPart = node;
  if (node >= 0) {
    gizmo.attach(current.nodes[node]);
    const name = current.rig.nodeInfo(node).name || `node ${node}`;
    selectionLabel.textContent = `Part: ${name}${current.parts.has(node) ? ' (hoses fixed to it)' : ''}`;
  } else {
    gizmo.detach();
    selectionLabel.textContent = '';
  }
}

function selectEnd(hose, end) {
  selectedEnd = { hose, end };
  selectionLabel.textContent = `Hose end: ${current.hoses[hose].info.id} end ${end} (U unplugs it)`;
}

/** Unplugs the selected hose end (U): it falls free (with gravity where the hose has it). */
function unplugSelectedEnd() {
  if (!current || !selectedEnd || drag) return;
  const hose = current.hoses[selectedEnd.hose];
  try {
    const socket = current.rig.unplug(hose.index, selectedEnd.end);
    hose.grabbable = new Set(current.rig.grabbablePoints(hose.index));
    selectionLabel.textContent = `${hose.info.id} end ${selectedEnd.end} unplugged` +
      (socket >= 0 ? ` from socket ${current.sockets[socket].id}` : '');
  } catch (error) {
    selectionLabel.textContent = error.message; // e.g. the end is not plugged
  }
}

// --- reel in, pay out: ] pays the selected hose out, [ reels it in, while held ----------------
const kReelSpeed = 0.5; // metres a second: a frame's reel is kReelSpeed × its time
const kScriptedReelSeconds = 1 / 90; // a frame of reel queued by the automation hook
const kReelReach = 0.3; // metres: how far beyond or short of its exported length a hose goes
let selectedHose = -1; // the hose last pressed on, or clicked in the panel
let reelKey = 0; // +1 while ] is held, -1 while [ is held
let reelScheduled = []; // frames of reel queued by the automation hook: +1 or -1 each, 1/90 s

/** The end whose attachment is a hose's reel outlet: its first end fixed to a part, else its
 * last; -1 when no end is fixed. */
function reelEnd(hose) {
  const rig = current.rig, last = rig.hoseInfo(hose).pointCount - 1;
  let end = -1;
  for (let a = rig.attachmentCount(hose) - 1; a >= 0; --a) {
    const pull = rig.attachmentPull(hose, a);
    if (pull.attached && pull.firstPoint === 0) end = 0;
    else if (pull.attached && pull.lastPoint === last && end < 0) end = 1;
  }
  return end;
}

function selectHose(index) {
  selectedHose = index;
  for (const hose of current.hoses) hose.row?.classList.toggle('selected', hose.index === index);
  showHoseSelection();
}

function showHoseSelection(reel = null) {
  if (selectedHose < 0 || !current) return;
  const hose = current.hoses[selectedHose];
  const length = current.rig.hoseInfo(selectedHose).restLength;
  const end = hose.info.isStatic ? -1 : (hose.reelEnd ??= reelEnd(selectedHose));
  selectionLabel.textContent = `Hose: ${hose.info.name || hose.info.id}, ${length.toFixed(3)} m` +
    (end < 0 ? ' (no end fixed: no reel)' : ` · ] pays out, [ reels in at its ${end === 0 ? 'first' : 'last'} end` +
      (reel?.clamped ? ` (${reel.message})` : ''));
}

/** `seconds` of reel on the selected hose: `direction` × kReelSpeed × seconds, within
 * kReelReach of its exported length (never below half of it). The same speed at any frame rate. */
function reelFrame(view, direction, seconds) {
  if (selectedHose < 0) return;
  const hose = view.hoses[selectedHose];
  if (hose.info.isStatic) return; // a static hose is on no reel
  const end = hose.reelEnd ??= reelEnd(selectedHose);
  if (end < 0) return;
  const exported = hose.info.restLength;
  const reel = view.rig.reel(selectedHose, end, direction * kReelSpeed * seconds,
    Math.max(0.5 * exported, exported - kReelReach), exported + kReelReach);
  hose.grabbable = new Set(view.rig.grabbablePoints(selectedHose)); // renumbered at the reel
  showHoseSelection(reel);
}

// Esc deselects; W and E switch the gizmo between moving and rotating (as three.js's editor);
// U unplugs the selected hose end; ] and [ held pay the selected hose out and reel it in.
window.addEventListener('keydown', (event) => {
  if (event.key === 'Escape' && current) selectPart(-1);
  else if (event.key === 'u' || event.key === 'U') unplugSelectedEnd();
  else if (event.key === 'w' || event.key === 'W') gizmo.setMode('translate');
  else if (event.key === 'e' || event.key === 'E') gizmo.setMode('rotate');
  else if (event.key === ']') reelKey = +1;
  else if (event.key === '[') reelKey = -1;
});
window.addEventListener('keyup', (event) => {
  if ((event.key === ']' && reelKey > 0) || (event.key === '[' && reelKey < 0)) reelKey = 0;
});

// --- VR controllers: squeeze or trigger on a hose holds the nearest point ---------------------
for (const index of [0, 1]) {
  const controller = renderer.xr.getController(index);
  const ray = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3(0, 0, -1)]),
    new THREE.LineBasicMaterial({ color: 0xffffff }));
  ray.scale.z = 2;
  controller.add(ray);
  controller.addEventListener('selectstart', () => {
    if (!current || drag) return;
    raycaster.setFromXRController(controller);
    const picked = pick(raycaster);
    if (!picked || picked.hose === undefined) return;
    const start = pointWorld(picked.hose, picked.point);
    const offset = start.sub(controller.getWorldPosition(new THREE.Vector3()));
    drag = { hose: picked.hose, point: picked.point, controller, offset, target: null };
  });
  controller.addEventListener('selectend', () => {
    if (drag?.controller === controller) endDrag();
  });
  scene.add(controller);
}

// In VR the rig stands in front of the viewer, its centre at chest height.
renderer.xr.addEventListener('sessionstart', () => {
  if (!current) return;
  const box = new THREE.Box3().setFromObject(current.gltf.scene);
  const centre = box.getCenter(new THREE.Vector3());
  rigRoot.position.set(-centre.x, 1.1 - centre.y, -0.6 - centre.z);
});
renderer.xr.addEventListener('sessionend', () => rigRoot.position.set(0, 0, 0));

// --- the frame -------------------------------------------------------------------------------
function trsOf(object) {
  const p = object.position, q = object.quaternion, s = object.scale;
  return [p.x, p.y, p.z, q.x, q.y, q.z, q.w, s.x, s.y, s.z];
}

// The frame's time for the runtime (seconds): the time since the last frame as the animation
// loop reports it, clamped to what update() accepts (a tab in the background, a hitch: 0.1 s);
// the first frame, 1/90 s.
const kLongestFrame = 0.1, kShortestFrame = 0.001;
let lastFrameTime = null;
function frameSeconds(time) {
  const seconds = lastFrameTime === null || !Number.isFinite(time) ? 1 / 90 : (time - lastFrameTime) / 1000;
  if (Number.isFinite(time)) lastFrameTime = time;
  return Math.min(kLongestFrame, Math.max(kShortestFrame, Number.isFinite(seconds) ? seconds : 1 / 90));
}

function frame(time) {
  const seconds = frameSeconds(time);
  if (current) {
    try {
      step(current, seconds);
    } catch (error) {
      showMessage(`The runtime refused a frame of ${current.name}.\n\n${error.message ?? error}`);
      console.error(error);
      current.rig.destroy();
      rigRoot.remove(current.gltf.scene);
      current = null;
      viewerState = 'error';
    }
  }
  renderer.render(scene, camera);
}

/** Each clip's ring where the runtime holds the clip now (it follows its node and, turning, the
 * hose); the points the clips hold are not picked for a grab. */
function placeClipRings(rig, hose) {
  hose.clipHeld.clear();
  const z = new THREE.Vector3(0, 0, 1);
  hose.clips.forEach((ring, c) => {
    const clip = rig.clipInfo(hose.index, c);
    ring.position.fromArray(clip.centre);
    ring.quaternion.setFromUnitVectors(z, new THREE.Vector3().fromArray(clip.axis));
    ring.material.color.copy(clip.gap > kClipMet ? clipOffColour : clipMetColour);
    ring.userData.gap = clip.gap;
    ring.userData.segment = clip.segment;
    hose.clipHeld.add(clip.segment).add(clip.segment + 1);
  });
}

function step(view, seconds) {
  const rig = view.rig;
  for (const node of view.movedParts) rig.setNodeTransform(node, trsOf(view.nodes[node]));
  view.movedParts.clear();
  if (drag) {
    if (drag.controller) {
      const hand = drag.controller.getWorldPosition(new THREE.Vector3()).add(drag.offset);
      drag.target = rigRoot.worldToLocal(hand).toArray();
    }
    if (drag.guide) {
      // Over to kGuideHeight above the socket (and kGuideBeyond beyond it), then down its axis,
      // kGuideStep a frame: the end is pulled in, its segment trailing along the axis.
      const socket = current.sockets[drag.guide.socket].info;
      const h = drag.guide.height;
      const aside = kGuideBeyond * (h - kGuideHeightMin) / (kGuideHeight - kGuideHeightMin);
      const goal = socket.position.map((x, k) => x + h * socket.axis[k] + aside * drag.guide.beyond[k]);
      const from = drag.guide.at ?? drag.target;
      const gap = Math.hypot(...goal.map((x, k) => x - from[k]));
      if (gap > kGuideStep) {
        drag.guide.at = from.map((x, k) => x + (goal[k] - x) * kGuideStep / gap);
      } else {
        drag.guide.at = goal;
        drag.guide.height = Math.max(kGuideHeightMin, h - kGuideStep);
      }
      drag.target = drag.guide.at;
    }
    rig.grab(drag.hose, drag.point, drag.target); // its outcome is in the frame's result
  }
  // A key held reels by the frame's time; a queued frame (the automation hook) by 1/90 s.
  const scripted = reelScheduled.length > 0;
  const reelDirection = scripted ? reelScheduled.shift() : reelKey;
  if (reelDirection !== 0) reelFrame(view, reelDirection, scripted ? kScriptedReelSeconds : seconds);
  rig.update(seconds);
  for (const hose of view.hoses) {
    if (hose.info.jointCount > 0) {
      const local = rig.jointPoses(hose.index, { world: false }).local;
      hose.bones.forEach((bone, j) => {
        bone.position.fromArray(local, 10 * j);
        bone.quaternion.fromArray(local, 10 * j + 3);
        bone.scale.fromArray(local, 10 * j + 7);
      });
    }
    placeClipRings(rig, hose);
    hose.grabbable = new Set(rig.grabbablePoints(hose.index)); // plugs and unplugs change them
    const result = rig.hoseResult(hose.index);
    if (touched(result) || hose.shown === null) hose.shown = result;
    hose.tension = tensionText(rig, hose);
    renderRow(hose);
  }
  placeSockets(rig);
  ++view.frames;
}

/** Each socket's ring where its part puts it now, green while free, blue while it holds an end. */
function placeSockets(rig) {
  const z = new THREE.Vector3(0, 0, 1);
  for (const socket of current.sockets) {
    socket.info = rig.socketInfo(socket.index);
    socket.ring.position.fromArray(socket.info.position);
    socket.ring.quaternion.setFromUnitVectors(z, new THREE.Vector3().fromArray(socket.info.axis));
    const colour = socket.info.occupantHose >= 0 ? socketHeldColour : socketFreeColour;
    socket.ring.material.color.copy(colour);
    socket.disc.material.color.copy(colour);
  }
}

// --- opening files ---------------------------------------------------------------------------
async function openFiles(files) {
  const main = files.find((f) => /\.glb$/i.test(f.name)) ?? files.find((f) => /\.gltf$/i.test(f.name));
  if (!main) {
    showMessage(`Could not open ${files.map((f) => f.name).join(', ')}.\n\n` +
      'Expected an exported .glb (or a .gltf with its .bin).');
    return;
  }
  const byName = new Map(files.map((f) => [f.name, f]));
  const readResource = async (uri) => {
    const file = byName.get(decodeURIComponent(uri).split('/').pop());
    if (!file) throw new Error(`${uri} was not opened with ${main.name}: open or drop it too`);
    return new Uint8Array(await file.arrayBuffer());
  };
  await openRig(main.name, new Uint8Array(await main.arrayBuffer()), readResource);
}

async function openUrl(url) {
  const absolute = new URL(url, location.href);
  const name = decodeURIComponent(absolute.pathname.split('/').pop() || url);
  const read = async (target) => {
    const response = await fetch(target);
    if (!response.ok) throw new Error(`${target}: the server answered ${response.status} ${response.statusText}`);
    return new Uint8Array(await response.arrayBuffer());
  };
  let bytes;
  try {
    bytes = await read(absolute.href);
  } catch (error) {
    viewerState = 'error';
    showMessage(`Could not open ${name}.\n\n${error.message ?? error}`);
    return;
  }
  await openRig(name, bytes, (uri) => read(new URL(uri, absolute).href));
}

fileInput.addEventListener('change', () => {
  if (fileInput.files.length > 0) openFiles([...fileInput.files]);
  fileInput.value = '';
});
window.addEventListener('dragover', (event) => {
  event.preventDefault();
  dropOverlay.hidden = false;
});
window.addEventListener('dragleave', (event) => {
  if (event.relatedTarget === null) dropOverlay.hidden = true;
});
window.addEventListener('drop', (event) => {
  event.preventDefault();
  dropOverlay.hidden = true;
  const files = [...(event.dataTransfer?.files ?? [])];
  if (files.length > 0) openFiles(files);
});

// --- the automation hook (tests; a console) ------------------------------------------------
function toScreen(world) {
  const rect = renderer.domElement.getBoundingClientRect();
  const ndc = world.clone().project(camera);
  return { x: rect.left + (ndc.x + 1) / 2 * rect.width, y: rect.top + (1 - ndc.y) / 2 * rect.height };
}

window.chaintubeViewer = {
  /** 'starting', 'ready' (no rig), 'loading', 'loaded' or 'error' */
  get state() { return viewerState; },
  get message() { return lastMessage; },
  get fileName() { return current?.name ?? null; },
  get frames() { return current?.frames ?? 0; },
  get selectedPart() { return selectedPart >= 0 ? current.rig.nodeInfo(selectedPart).name : null; },
  get gizmoAxis() { return gizmo.axis; },
  get gizmoDragging() { return gizmo.dragging; },
  open: openUrl,
  /** The panel's rows: [{ id, status, flags, tension (each attachment's tautness) }]. */
  panel() {
    return [...hoseTable.children].map((row) => ({
      id: row.dataset.hose, status: row.children[1].textContent, flags: row.children[2].textContent,
      tension: row.children[3].textContent,
    }));
  },
  /** The recorded inputs (record=1) and every joint's bone world position in the rig's frame. */
  snapshot() {
    rigRoot.updateMatrixWorld(true);
    const inverse = rigRoot.matrixWorld.clone().invert();
    return {
      inputs: current.rig.recordedInputs(),
      hoses: current.hoses.map((hose) => ({
        id: hose.info.id,
        joints: hose.bones.map((bone) => bone.getWorldPosition(new THREE.Vector3()).applyMatrix4(inverse).toArray()),
      })),
    };
  },
  /** The hose selected for the reel keys (its id), or null. */
  get selectedHose() { return selectedHose >= 0 ? current.hoses[selectedHose].info.id : null; },
  /** Selects hose `id` for the reel keys, as a click on its row does. */
  selectHose(id) { selectHose(current.rig.findHose(id)); },
  /** Queues `frames` frames of reel on the selected hose, each as a frame of 1/90 s with ] (+1)
   * or [ (-1) held does (kReelSpeed / 90 m a frame, whatever the display's rate); resolves when
   * they ran. */
  reelFrames(frames, direction) {
    reelScheduled.push(...Array(frames).fill(Math.sign(direction)));
    return new Promise((resolve) => {
      const wait = () => (reelScheduled.length === 0 ? resolve() : requestAnimationFrame(wait));
      wait();
    });
  },
  /** Hose `id`'s rest length and axis point count now. */
  hoseLength(id) {
    const info = current.rig.hoseInfo(current.rig.findHose(id));
    return { restLength: info.restLength, pointCount: info.pointCount };
  },
  /** The hoses' descriptor ids, in rig order. */
  hoseIds() { return current.hoses.map((hose) => hose.info.id); },
  /** The clip rings as drawn, in the rig's frame: [{ hose (id), clip, centre [x, y, z], axis
   * [x, y, z] (the ring's normal), gap (metres), segment (points segment and segment + 1 are
   * held), colour (hex) }]. */
  clipRings() {
    rigRoot.updateMatrixWorld(true);
    const inverse = rigRoot.matrixWorld.clone().invert();
    return current.hoses.flatMap((hose) => hose.clips.map((ring, clip) => ({
      hose: hose.info.id, clip,
      centre: ring.getWorldPosition(new THREE.Vector3()).applyMatrix4(inverse).toArray(),
      axis: new THREE.Vector3(0, 0, 1).applyQuaternion(ring.quaternion).toArray(),
      gap: ring.userData.gap, segment: ring.userData.segment, colour: ring.material.color.getHex(),
    })));
  },
  /** The sockets as drawn, in the rig's frame: [{ id, position [x, y, z], axis [x, y, z] (the
   * ring's normal), occupant ({ hose (id), end } or null), colour (hex) }]. */
  sockets() {
    rigRoot.updateMatrixWorld(true);
    const inverse = rigRoot.matrixWorld.clone().invert();
    return current.sockets.map((socket) => ({
      id: socket.id,
      position: socket.ring.getWorldPosition(new THREE.Vector3()).applyMatrix4(inverse).toArray(),
      axis: new THREE.Vector3(0, 0, 1).applyQuaternion(socket.ring.quaternion).toArray(),
      occupant: socket.info.occupantHose >= 0
        ? { hose: current.hoses[socket.info.occupantHose].info.id, end: socket.info.occupantEnd } : null,
      colour: socket.ring.material.color.getHex(),
    }));
  },
  /** Where socket `id` is on the screen (CSS pixels). */
  screenOfSocket(id) {
    const socket = current.sockets.find((s) => s.id === id);
    return toScreen(rigRoot.localToWorld(new THREE.Vector3().fromArray(socket.info.position)));
  },
  /** The selected hose end (U unplugs it): { hose (id), end } or null. */
  get selectedEnd() {
    return selectedEnd ? { hose: current.hoses[selectedEnd.hose].info.id, end: selectedEnd.end } : null;
  },
  /** The dragged end's guide into a socket: the socket's id, or null. */
  get guidedInto() { return drag?.guide ? current.sockets[drag.guide.socket].id : null; },
  /** The runtime's clip count of every hose, summed. */
  clipCount() { return current.hoses.reduce((sum, hose) => sum + current.rig.clipCount(hose.index), 0); },
  /** The axis points of hose `id` a hand may grab. */
  grabbablePoints(id) { return [...current.hoses[current.rig.findHose(id)].grabbable]; },
  /** The nodes hoses are fixed to, most hoses first: [{ name, node, trs (its local transform),
   * fixedJoints: [{ hose (id), joint }] }]. */
  parts() {
    const hoseCount = (joints) => new Set(joints.map((j) => j.hose)).size;
    return [...current.parts].sort((a, b) => hoseCount(b[1]) - hoseCount(a[1])).map(([node, fixedJoints]) => ({
      name: current.rig.nodeInfo(node).name, node, trs: [...current.rig.nodeTransform(node)], fixedJoints,
    }));
  },
  /** What a press at (x, y) (CSS pixels) picks: { hose (id), point }, { part (name) } or null. */
  pickAt(x, y) {
    const picked = pick(rayFromEvent({ clientX: x, clientY: y }));
    if (!picked) return null;
    if (picked.hose !== undefined) return { hose: current.hoses[picked.hose].info.id, point: picked.point, end: picked.end };
    const node = partOf(picked.object);
    return { part: node >= 0 ? current.rig.nodeInfo(node).name : null };
  },
  /** Where axis point `point` of hose `id` is on the screen (CSS pixels). */
  screenOfPoint(id, point) {
    const hose = current.rig.findHose(id);
    return toScreen(pointWorld(hose, point));
  },
  /** A pixel where the part node `name` is the first thing seen, or null. */
  screenOnPart(name) {
    const node = current.rig.findNode(name);
    const candidates = [];
    current.nodes[node].traverse((o) => {
      if (!o.isMesh || current.hoseOfMesh.has(o)) return;
      const position = o.geometry.attributes.position;
      for (let i = 0; i < position.count; i += Math.max(1, Math.floor(position.count / 200))) {
        const a = new THREE.Vector3().fromBufferAttribute(position, i);
        const b = new THREE.Vector3().fromBufferAttribute(position, (i + 1) % position.count);
        const c = new THREE.Vector3().fromBufferAttribute(position, (i + 2) % position.count);
        candidates.push(o.localToWorld(a.clone().add(b).add(c).divideScalar(3)));
        candidates.push(o.localToWorld(a.lerp(b, 0.5)));
      }
    });
    // A spot whose neighbours 4 px around are on the part too, so a click there is not on a
    // silhouette edge or on a hose drawn over the part.
    const onPart = (x, y) => {
      const picked = pick(rayFromEvent({ clientX: x, clientY: y }));
      return picked?.object !== undefined && partOf(picked.object) === node;
    };
    for (const world of candidates) {
      const screen = toScreen(world);
      if ([[0, 0], [4, 0], [-4, 0], [0, 4], [0, -4]].every(([dx, dy]) => onPart(screen.x + dx, screen.y + dy)))
        return screen;
    }
    return null;
  },
  /** A point on the gizmo's arrow for `axis` ('X', 'Y', 'Z') and the screen direction of a
   * move along it (pixels per metre), or null when nothing is selected. */
  gizmoHandle(axis) {
    if (selectedPart < 0) return null;
    const object = current.nodes[selectedPart];
    const origin = object.getWorldPosition(new THREE.Vector3());
    // TransformControls scales its handles by this factor (its updateMatrixWorld).
    const factor = origin.distanceTo(camera.position) *
      Math.min(1.9 * Math.tan(Math.PI * camera.fov / 360) / camera.zoom, 7) * gizmo.size / 4;
    const direction = new THREE.Vector3(axis === 'X' ? 1 : 0, axis === 'Y' ? 1 : 0, axis === 'Z' ? 1 : 0);
    const handle = toScreen(origin.clone().addScaledVector(direction, 0.45 * factor));
    const a = toScreen(origin), b = toScreen(origin.clone().add(direction));
    return { x: handle.x, y: handle.y, dx: b.x - a.x, dy: b.y - a.y };
  },
};

runtimePromise.then(() => {
  viewerState = 'ready';
  const file = params.get('file');
  if (file) openUrl(file);
}).catch((error) => {
  viewerState = 'error';
  showMessage(error.message ?? String(error));
});

renderer.setAnimationLoop(frame);
