# Imports exported GLB/glTF files into Blender (headless) and checks the hose rigs.
#   blender -b --factory-startup --python-exit-code 3 --python blender_import.py -- [--one-armature-per-hose] FILE.glb …
# Per file: the importer succeeds; every skinned hose of the descriptor becomes a mesh object
# with an Armature modifier whose vertex groups are exactly the hose's joints (one per axis
# point), each a bone of that armature; every static hose ("static": true) becomes a plain mesh
# object (no Armature modifier) lying on its axis.
#
# Armatures. Blender's importer puts a skin's armature at the deepest common ancestor (DCA) of
# its joints and turns every node between a joint and that ancestor into a bone; a node can be a
# bone of one armature only. So two hoses share an armature exactly when their *spans* share a
# node, where a hose's span is the set of nodes on the paths from its joints' parents up to the
# DCA (inclusive). The exporter hangs the joints of a hose fixed to one scene node (or to none)
# under the hose's own "<id> joints" node, so its span is that node alone: such a hose always has
# an armature of its own, with exactly its joints as bones. A hose fixed to several scene nodes
# has those nodes and their ancestors up to the DCA in its span; hoses whose spans overlap share
# one armature. This test computes the spans from the file and asserts exactly that: hoses in
# one connected group of overlapping spans share one armature, hoses in different groups have
# different armatures. With --one-armature-per-hose (files exported with --joints-at-root) it
# also asserts that every hose's armature has exactly its joints as bones.
# Any failed check makes Blender exit with 3.
import json
import struct
import sys

import numpy  # Blender 3.4's glTF importer uses numpy.bool, removed in numpy ≥ 1.24
if not hasattr(numpy, "bool"):
    numpy.bool = bool
import bpy
from mathutils import Vector
from mathutils.geometry import intersect_point_line


def descriptor_of(path):
    with open(path, "rb") as stream:
        data = stream.read()
    if data[:4] == b"glTF":
        length = struct.unpack_from("<I", data, 12)[0]
        document = json.loads(data[20:20 + length])
    else:
        document = json.loads(data)
    return document["extensions"]["CHAINTUBE_hose_rig"], document


def expected_groups(document, hoses):
    """Hose id → group number: hoses whose spans overlap (transitively) share a group."""
    parent = {}
    for index, node in enumerate(document["nodes"]):
        for child in node.get("children", []):
            parent[child] = index

    def path_from_root(node):
        path = []
        while node is not None:
            path.append(node)
            node = parent.get(node)
        return path[::-1]

    spans = {}
    for hose in hoses:
        joints = set(hose["joints"])
        paths = [path_from_root(j) for j in hose["joints"]]
        common = paths[0]
        for path in paths[1:]:
            k = 0
            while k < min(len(common), len(path)) and common[k] == path[k]:
                k += 1
            common = common[:k]
        dca = common[-1] if common else "root"  # Blender adds a dummy root above the scene roots
        if dca in joints:
            dca = parent.get(dca, "root")
        span = {dca}
        for path in paths:
            start = path.index(dca) if dca in path else 0
            span.update(n for n in path[start:] if n not in joints)
        spans[hose["id"]] = span
    ids = list(spans)
    representative = {h: h for h in ids}

    def root(h):
        while representative[h] != h:
            h = representative[h]
        return h

    for i, a in enumerate(ids):
        for b in ids[i + 1:]:
            if spans[a] & spans[b]:
                representative[root(a)] = root(b)
    return {h: root(h) for h in ids}


def distance_to_polyline(point, axis):
    best = float("inf")
    for a, b in zip(axis, axis[1:]):
        closest, t = intersect_point_line(point, a, b)
        if t < 0:
            closest = a
        elif t > 1:
            closest = b
        best = min(best, (closest - point).length)
    return best


def gltf_to_blender(p):  # glTF +Y up → Blender +Z up
    return Vector((p[0], -p[2], p[1]))


failures = []
arguments = sys.argv[sys.argv.index("--") + 1:]
one_armature_per_hose = "--one-armature-per-hose" in arguments
for path in [a for a in arguments if not a.startswith("--")]:
    before = len(failures)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.import_scene.gltf(filepath=path, import_shading="SMOOTH")
    if result != {"FINISHED"}:
        failures.append(f"{path}: import returned {result}")
        continue
    descriptor, document = descriptor_of(path)
    skinned_hoses = [h for h in descriptor["hoses"] if h["skin"] >= 0]
    static_hoses = [h for h in descriptor["hoses"] if h.get("static")]
    joint_names = {h["id"]: {document["nodes"][j]["name"] for j in h["joints"]} for h in skinned_hoses}
    # Hoses fixed to at most one scene node: the exporter promises an armature of their own.
    own_promised = {h["id"] for h in skinned_hoses
                    if len({a["node"] for a in h["attachments"]}) <= 1}
    groups = expected_groups(document, skinned_hoses)
    armature_of = {}
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        modifiers = [m for m in obj.modifiers if m.type == "ARMATURE" and m.object]
        if not modifiers:
            continue
        vertex_groups = {group.name for group in obj.vertex_groups}
        hose = next((h for h, names in joint_names.items() if names == vertex_groups), None)
        if hose is None:
            failures.append(f"{path}: skinned object {obj.name!r} has vertex groups matching no hose")
            continue
        bones = {bone.name for bone in modifiers[0].object.data.bones}
        if (one_armature_per_hose or hose in own_promised) and bones != vertex_groups:
            failures.append(f"{path}: hose {hose}: its armature has {len(bones)} bones, "
                            f"expected exactly its {len(vertex_groups)} joints")
        missing = vertex_groups - bones
        if missing:
            failures.append(f"{path}: hose {hose}: joints without a bone: {sorted(missing)[:3]}")
        armature_of[hose] = modifiers[0].object
    for hose in joint_names:
        if hose not in armature_of:
            failures.append(f"{path}: hose {hose} did not become a skinned mesh object")
    for hose in own_promised:
        if any(groups[other] == groups[hose] for other in groups if other != hose):
            failures.append(f"{path}: hose {hose} is fixed to at most one scene node but its span "
                            f"overlaps another hose's")
    ids = sorted(armature_of)
    for i, a in enumerate(ids):
        for b in ids[i + 1:]:
            same = armature_of[a] == armature_of[b]
            if one_armature_per_hose and same:
                failures.append(f"{path}: hoses {a} and {b} share armature {armature_of[a].name!r}")
            elif same != (groups[a] == groups[b]):
                failures.append(f"{path}: hoses {a} and {b}: expected "
                                f"{'one shared armature' if groups[a] == groups[b] else 'different armatures'}"
                                f", got {armature_of[a].name!r} and {armature_of[b].name!r}")
    # Static hoses: plain mesh objects on their axis (vertices within the radius of the axis).
    for hose in static_hoses:
        label = hose["name"] or hose["id"]
        axis = [gltf_to_blender(p) for p in hose["axis"]]
        bound = (hose["radius"] if hose["crossSection"]["shape"] == "circle"
                 else hose["outerDiameter"]) * (1 + 1e-5) + 1e-6
        candidates = [o for o in bpy.data.objects if o.type == "MESH"
                      and (o.name == label or o.name.startswith(label + "."))
                      and not any(m.type == "ARMATURE" for m in o.modifiers)]
        placed = False
        for obj in candidates:
            world = [obj.matrix_world @ v.co for v in obj.data.vertices]
            if world and max(distance_to_polyline(p, axis) for p in world) <= bound:
                placed = True
        if not placed:
            failures.append(f"{path}: static hose {hose['id']}: no plain mesh object {label!r} "
                            f"lies on its axis ({len(candidates)} candidate(s))")
    armatures = [obj for obj in bpy.data.objects if obj.type == "ARMATURE"]
    if one_armature_per_hose and len(armatures) != len(joint_names):
        failures.append(f"{path}: {len(armatures)} armatures for {len(joint_names)} hoses")
    own = sum(1 for h in armature_of if list(armature_of.values()).count(armature_of[h]) == 1)
    print(f"{'PASS' if len(failures) == before else 'FAIL'} {path}: {len(armature_of)} of "
          f"{len(joint_names)} hoses skinned, one vertex group per axis point; "
          f"{len(armatures)} armature object(s), {own} hose(s) with an armature of their own "
          f"({len(set(groups.values()))} expected group(s)); {len(static_hoses)} static plain mesh(es)")

for failure in failures:
    print("  " + failure)
if failures:
    raise RuntimeError(f"{len(failures)} check(s) failed")  # --python-exit-code makes this exit 3
