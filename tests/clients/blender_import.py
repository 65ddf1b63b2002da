# Imports exported GLB/glTF files into Blender (headless) and checks the hose rigs.
#   blender -b --factory-startup --python-exit-code 3 --python blender_import.py -- [--one-armature-per-hose] FILE.glb …
# Per file: the importer succeeds; every skinned hose of the descriptor becomes a mesh object
# with an Armature modifier whose vertex groups are exactly the hose's joints (one per axis
# point), each a bone of that armature. With --one-armature-per-hose (files exported with
# --joints-at-root) every hose also has an armature of its own. Blender's importer puts one
# armature at the deepest common ancestor of a skin's joints, so hoses whose joints hang under
# the same scene objects share one. Any failed check makes Blender exit with 3.
import json
import struct
import sys

import numpy  # Blender 3.4's glTF importer uses numpy.bool, removed in numpy ≥ 1.24
if not hasattr(numpy, "bool"):
    numpy.bool = bool
import bpy


def descriptor_of(path):
    with open(path, "rb") as stream:
        data = stream.read()
    if data[:4] == b"glTF":
        length = struct.unpack_from("<I", data, 12)[0]
        document = json.loads(data[20:20 + length])
    else:
        document = json.loads(data)
    return document["extensions"]["CHAINTUBE_hose_rig"], document


failures = []
arguments = sys.argv[sys.argv.index("--") + 1:]
one_armature_per_hose = "--one-armature-per-hose" in arguments
for path in [a for a in arguments if not a.startswith("--")]:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.import_scene.gltf(filepath=path, import_shading="SMOOTH")
    if result != {"FINISHED"}:
        failures.append(f"{path}: import returned {result}")
        continue
    descriptor, document = descriptor_of(path)
    joint_names = {}
    for hose in descriptor["hoses"]:
        if hose["skin"] >= 0:
            joint_names[hose["id"]] = {document["nodes"][j]["name"] for j in hose["joints"]}
    matched = set()
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        modifiers = [m for m in obj.modifiers if m.type == "ARMATURE" and m.object]
        if not modifiers:
            continue
        groups = {group.name for group in obj.vertex_groups}
        hose = next((h for h, names in joint_names.items() if names == groups), None)
        if hose is None:
            failures.append(f"{path}: skinned object {obj.name!r} has vertex groups matching no hose")
            continue
        bones = {bone.name for bone in modifiers[0].object.data.bones}
        if one_armature_per_hose and bones != groups:
            failures.append(f"{path}: hose {hose}: its armature has {len(bones)} bones, "
                            f"expected exactly its {len(groups)} joints")
        missing = groups - bones
        if missing:
            failures.append(f"{path}: hose {hose}: joints without a bone: {sorted(missing)[:3]}")
        matched.add(hose)
    for hose in joint_names:
        if hose not in matched:
            failures.append(f"{path}: hose {hose} did not become a skinned mesh object")
    armatures = [obj for obj in bpy.data.objects if obj.type == "ARMATURE"]
    if one_armature_per_hose and len(armatures) != len(joint_names):
        failures.append(f"{path}: {len(armatures)} armatures for {len(joint_names)} hoses")
    print(f"{'PASS' if not failures else 'FAIL'} {path}: {len(matched)} of {len(joint_names)} hoses "
          f"skinned, one vertex group per axis point; {len(armatures)} armature object(s)")

for failure in failures:
    print("  " + failure)
if failures:
    raise RuntimeError(f"{len(failures)} check(s) failed")  # --python-exit-code makes this exit 3
