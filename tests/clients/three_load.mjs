// Loads exported files with three.js GLTFLoader in Node (no DOM) and checks the hose rigs.
//   node three_load.mjs [--joints-at-root] FILE.glb|FILE.gltf …
// Per file: the file parses; the CHAINTUBE_hose_rig extension is visible in
// gltf.userData.gltfExtensions; every skinned hose of the descriptor is a SkinnedMesh with one
// bone per axis point; each bone's world position is its axis point (1e-5 m); skinning the bind
// pose reproduces the exported vertices (1e-5 m); moving the scene node a hose is attached to
// carries the attached bones with it (not for files exported with --joints-at-root, where
// joints deliberately do not hang under scene nodes). Every static hose ("static": true) is a
// plain Mesh (not skinned) whose world-space vertices lie on the hose (within its radius of the
// axis polyline, and reaching both ends), and moving its attachment node carries the mesh.
// Exit 0 only if every check passes.
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { readFile } from 'node:fs/promises';
import path from 'node:path';

globalThis.ProgressEvent ??= class extends Event {
  constructor(type, init = {}) { super(type); Object.assign(this, init); }
};

const failures = [];
const check = (condition, message) => { if (!condition) failures.push(message); return condition; };

async function load(file) {
  const bytes = await readFile(file);
  const manager = new THREE.LoadingManager();
  const folder = path.dirname(path.resolve(file));
  // Node's fetch cannot read files: hand external resources over as data URIs.
  const external = new Map();
  if (file.endsWith('.gltf')) {
    for (const buffer of JSON.parse(bytes.toString('utf8')).buffers ?? [])
      if (buffer.uri && !buffer.uri.startsWith('data:'))
        external.set(buffer.uri, 'data:application/octet-stream;base64,' +
                     (await readFile(path.join(folder, decodeURIComponent(buffer.uri)))).toString('base64'));
  }
  manager.setURLModifier((url) => external.get(url.split('/').pop()) ?? url);
  const loader = new GLTFLoader(manager);
  const data = file.endsWith('.gltf') ? bytes.toString('utf8')
                                      : bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  return loader.parseAsync(data, folder + '/');
}

// Distance from p to the polyline through the points.
function distanceToPolyline(p, points) {
  let best = Infinity;
  const segment = new THREE.Line3(), closest = new THREE.Vector3();
  for (let i = 0; i + 1 < points.length; ++i) {
    segment.set(points[i], points[i + 1]);
    segment.closestPointToPoint(p, true, closest);
    best = Math.min(best, closest.distanceTo(p));
  }
  return best;
}

function checkStaticHose(file, gltf, hose, mesh) {
  if (!check(mesh.isMesh && !mesh.isSkinnedMesh,
             `${file}: static hose ${hose.id}: node ${hose.mesh} is not a plain Mesh`)) return;
  gltf.scene.updateMatrixWorld(true);
  const axis = hose.axis.map((p) => new THREE.Vector3(...p));
  // A circle's ring vertices are exactly one radius from their ring centre (on the axis); other
  // cross-sections are only bounded by the outer diameter.
  const bound = (hose.crossSection.shape === 'circle' ? hose.radius : hose.outerDiameter) * (1 + 1e-5) + 1e-6;
  const attribute = mesh.geometry.attributes.position;
  const vertex = new THREE.Vector3();
  let worst = 0, nearFirst = Infinity, nearLast = Infinity;
  for (let v = 0; v < attribute.count; ++v) {
    vertex.fromBufferAttribute(attribute, v).applyMatrix4(mesh.matrixWorld);
    worst = Math.max(worst, distanceToPolyline(vertex, axis));
    nearFirst = Math.min(nearFirst, vertex.distanceTo(axis[0]));
    nearLast = Math.min(nearLast, vertex.distanceTo(axis[axis.length - 1]));
  }
  check(worst <= bound, `${file}: static hose ${hose.id}: a vertex is ${worst} m from the axis (bound ${bound})`);
  check(nearFirst <= bound && nearLast <= bound,
        `${file}: static hose ${hose.id}: the mesh does not reach both ends of the axis ` +
        `(${nearFirst} m, ${nearLast} m)`);
}

const jointsAtRoot = process.argv.includes('--joints-at-root');
for (const file of process.argv.slice(2).filter((a) => !a.startsWith('--'))) {
  const before = failures.length;
  let gltf;
  try {
    gltf = await load(file);
  } catch (error) {
    check(false, `${file}: GLTFLoader failed: ${error.message}`);
    continue;
  }
  const descriptor = gltf.userData?.gltfExtensions?.CHAINTUBE_hose_rig;
  if (!check(descriptor, `${file}: CHAINTUBE_hose_rig not in gltf.userData.gltfExtensions`)) continue;
  gltf.scene.updateMatrixWorld(true);
  const skinned = [];
  gltf.scene.traverse((o) => { if (o.isSkinnedMesh) skinned.push(o); });
  check(skinned.length === descriptor.hoses.filter((h) => h.skin >= 0).length,
        `${file}: ${skinned.length} SkinnedMesh objects for ${descriptor.hoses.length} hoses`);
  let worstBone = 0, worstVertex = 0, staticCount = 0;
  for (const hose of descriptor.hoses) {
    const mesh = await gltf.parser.getDependency('node', hose.mesh);
    if (hose.static) {
      ++staticCount;
      checkStaticHose(file, gltf, hose, mesh);
      const attachmentNode = hose.attachments[0].node;
      if (attachmentNode >= 0) {
        const node = await gltf.parser.getDependency('node', attachmentNode);
        const vertex = (m) => new THREE.Vector3().fromBufferAttribute(m.geometry.attributes.position, 0)
          .applyMatrix4(m.matrixWorld);
        const start = vertex(mesh), nodeStart = node.getWorldPosition(new THREE.Vector3());
        node.position.y += 0.1;
        gltf.scene.updateMatrixWorld(true);
        const moved = vertex(mesh).sub(start);
        const nodeMoved = node.getWorldPosition(new THREE.Vector3()).sub(nodeStart);
        check(nodeMoved.length() > 1e-3 && moved.distanceTo(nodeMoved) < 1e-5,
              `${file}: static hose ${hose.id}: moving node ${attachmentNode} by ${nodeMoved.toArray()} ` +
              `moved its mesh by ${moved.toArray()}`);
        node.position.y -= 0.1;
        gltf.scene.updateMatrixWorld(true);
      }
      continue;
    }
    if (!check(mesh.isSkinnedMesh, `${file}: hose ${hose.id}: node ${hose.mesh} is not a SkinnedMesh`)) continue;
    const bones = mesh.skeleton.bones;
    check(bones.length === hose.axis.length,
          `${file}: hose ${hose.id}: ${bones.length} bones for ${hose.axis.length} axis points`);
    const position = new THREE.Vector3();
    bones.forEach((bone, i) => {
      bone.getWorldPosition(position);
      worstBone = Math.max(worstBone, position.distanceTo(new THREE.Vector3(...hose.axis[i])));
    });
    const attribute = mesh.geometry.attributes.position;
    const skinnedVertex = new THREE.Vector3();
    for (let v = 0; v < attribute.count; v += 7) {
      skinnedVertex.fromBufferAttribute(attribute, v);
      const bind = skinnedVertex.clone();
      mesh.applyBoneTransform(v, skinnedVertex);
      worstVertex = Math.max(worstVertex, skinnedVertex.distanceTo(bind));
    }
    // Moving the node of the first attachment carries the bones of its points.
    const attachment = hose.attachments.find((a) => a.node >= 0);
    if (attachment && !jointsAtRoot) {
      const node = await gltf.parser.getDependency('node', attachment.node);
      const bone = bones[attachment.points[0]];
      const start = bone.getWorldPosition(new THREE.Vector3());
      const nodeStart = node.getWorldPosition(new THREE.Vector3());
      node.position.x += 0.1;
      gltf.scene.updateMatrixWorld(true);
      const moved = bone.getWorldPosition(new THREE.Vector3()).sub(start);
      const nodeMoved = node.getWorldPosition(new THREE.Vector3()).sub(nodeStart);
      check(nodeMoved.length() > 1e-3 && moved.distanceTo(nodeMoved) < 1e-5,
            `${file}: hose ${hose.id}: moving node ${attachment.node} by ${nodeMoved.toArray()} ` +
            `moved its attached bone by ${moved.toArray()}`);
      node.position.x -= 0.1;
      gltf.scene.updateMatrixWorld(true);
    }
  }
  check(worstBone < 1e-5, `${file}: a bone is ${worstBone} m from its axis point`);
  check(worstVertex < 1e-5, `${file}: skinning the bind pose moves a vertex by ${worstVertex} m`);
  console.log(`${failures.length === before ? 'PASS' : 'FAIL'} ${file}: ${skinned.length} skinned meshes, ` +
              `${staticCount} static plain meshes, ` +
              `bones within ${worstBone.toExponential(1)} m of the axis, bind-pose skinning within ` +
              `${worstVertex.toExponential(1)} m`);
}
for (const failure of failures) console.log(`  ${failure}`);
process.exit(failures.length ? 1 : 0);
