#!/usr/bin/env python3
"""Writes the sample projects and the small test-rig scene.

The .ctproj files this writes are then put into canonical form by
`ctproj-canonicalise --root scenes=<scenes dir> samples/*.ctproj` (formats/tools), and the
canonical output is what is committed. Run from the repository root:

    python3 samples/generate_samples.py && build/formats/ctproj-canonicalise \
        --root scenes=../shared/scenes samples/*.ctproj
"""
import base64
import json
import math
import random
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent

PRESETS = [
    {"name": "PVC hose", "description": "Clear PVC suction/delivery hose with textile braid, 19 mm ID",
     "expansionCoefficient": 0.05, "bendLimit": {"minBendRadius": 0.1}},
    {"name": "rubber hose", "description": "EPDM coolant/air hose, 20 mm ID",
     "expansionCoefficient": 0.08, "bendLimit": {"minBendRadius": 0.12}},
    {"name": "braided steel hose", "description": "PTFE hose with stainless-steel overbraid, -12 (19 mm)",
     "expansionCoefficient": 0.01, "bendLimit": {"minBendRadius": 0.165}},
    {"name": "cable bundle", "description": "Wire harness bundle in corrugated sleeve, 20 mm",
     "expansionCoefficient": 0.02, "bendLimit": {"minBendRadius": 0.08}},
]
IDENTITY = {"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 0.0, 1.0]}


def project(name, scenes, hoses, export_path):
    return {"format": "chaintube-project", "version": "1.2", "name": name, "scenes": scenes,
            "materialPresets": PRESETS, "hoses": hoses, "poses": [], "colliders": [],
            "export": {"format": "glb", "path": export_path, "includeScene": bool(scenes)}}


def hose(hose_id, name, route, material, diameter, colour, attachments=(), segments=None,
         segment_length=None, profile=None, roughness=0.6, fittings_allowance=0.0):
    h = {"id": hose_id, "name": name, "route": [[round(c, 7) for c in p] for p in route],
         "material": material, "profile": profile or {"shape": "circle", "sides": 16},
         "outerDiameter": diameter}
    if segments is not None:
        h["segmentCount"] = segments
    else:
        h["segmentLength"] = segment_length
    h.update({"colour": colour, "roughness": roughness, "attachments": list(attachments)})
    if fittings_allowance:  # project format 1.6: the end fittings' share of the cut length
        h["fittingsAllowance"] = fittings_allowance
    return h


def attachment(scene, node, first, last, offset=IDENTITY):
    return {"scene": scene, "node": node, "offset": offset, "points": [first, last]}


def clip(scene, node, place, offset=IDENTITY, hold="sliding"):
    """A clip (project format 1.5) on `node`, where the hose is `place` metres (rest arc length)
    from its first point."""
    return {"scene": scene, "node": node, "offset": offset, "place": place, "hold": hold}


def clip_hose(hose_id, name, route, material, diameter, colour, attachments, clips, **options):
    h = hose(hose_id, name, route, material, diameter, colour, attachments, **options)
    h["clips"] = list(clips)
    return h


def socket(socket_id, scene, node, position, axis, tag, capture_radius=0.03, capture_angle=0.5):
    """A socket (project format 1.7): a coupling on `node` a hose end with plug `tag` fits;
    position and axis in the node's frame."""
    return {"id": socket_id, "scene": scene, "node": node, "position": position, "axis": axis,
            "captureRadius": capture_radius, "captureAngle": capture_angle, "tag": tag}


def write(name, document):
    (HERE / name).write_text(json.dumps(document, indent=2) + "\n")


# --- single-hose: the paper's setting ---------------------------------------------------------
write("single-hose.ctproj", project("Single hose (paper setting)", [], [
    hose("hose-1", "12-segment hose", [[0.0, 0.5, 0.0], [0.6, 0.5, 0.0]],
         {"expansionCoefficient": 0.2, "bendLimit": {"deflectionAngle": 0.6981317007977318}},
         0.03, [0.85, 0.45, 0.1, 1.0], segments=12)], "single-hose.glb"))

# --- engine: hoses fixed to parts of the Khronos 2CylinderEngine (millimetre CAD data) ------------
ENGINE_NODES = {  # node path → world position of its origin in metres (ctscene-dump, 1 mm units)
    "/ROOT/node_1/node_1_11/Piston_123-844_0_Parts_1": (0.1578, -0.0095, 0.0200),
    "/ROOT/node_1/node_1_12/Piston_123-844_0_Parts_1": (-0.1578, 0.0095, -0.0200),
    "/ROOT/node_1/node_1_8/body_4": (0.2240, 0.0305, 0.0250),
    "/ROOT/node_1/node_1_8/node_1_8_8/body_8": (-0.2240, 0.0305, -0.0150),
    "/ROOT/node_1/node_1_8/body_2": (0.1269, 0.0, -0.0366),
    "/ROOT/node_1/node_1_8/body_3": (-0.1269, 0.0, 0.0366),
    "/ROOT/node_1/node_1_9/body_21": (-0.0341, -0.0060, -0.1290),
    "/ROOT/node_1/node_1_10/body_22": (0.0, 0.0, 0.0020),
    "/ROOT/node_1/rod_123-699_0_Parts_1": (0.0710, 0.0222, 0.0220),
    "/ROOT/node_1/rod_123-699_0_Parts_1#2": (-0.0710, -0.0222, -0.0200),
    "/ROOT/node_1/node_1_8/node_1_8_8/body_11": (-0.2620, 0.2240, 0.0101),
    "/ROOT/node_1/node_1_8/body_6": (0.0650, 0.1287, -0.0033),
}
ENGINE_SCENE = [{"id": "engine", "path": "scenes:2CylinderEngine.glb",
                 "import": {"metresPerUnit": 0.001, "chordalTolerance": 0.0001,
                            "angularTolerance": 0.5}}]
PRESET_NAMES = [p["name"] for p in PRESETS]


MIN_BEND_RADIUS = {p["name"]: p["bendLimit"]["minBendRadius"] for p in PRESETS}
# Routes bend this much more gently than the material allows, so that the built hoses (corners
# filleted, then resampled to the axis resolution) stay within the limit: `chaintube validate`
# reports no joint below the minimum bend radius.
BEND_MARGIN = 1.3


def arc_route(a, b, lift, min_bend_radius, points):
    """A route from a to b along a circular arc bulging upwards by at most `lift` metres, whose
    radius is at least BEND_MARGIN × min_bend_radius (a gentler bulge where the parts are close
    together), sampled at `points` points equally spaced along the arc."""
    d = [b[k] - a[k] for k in range(3)]
    chord = math.sqrt(sum(c * c for c in d))
    unit = [c / chord for c in d]
    # Bulge direction: "up" made perpendicular to the chord (x if the chord is vertical).
    up = [0.0, 1.0, 0.0]
    if abs(unit[1]) > 0.99:
        up = [1.0, 0.0, 0.0]
    dot = sum(up[k] * unit[k] for k in range(3))
    normal = [up[k] - dot * unit[k] for k in range(3)]
    length = math.sqrt(sum(c * c for c in normal))
    normal = [c / length for c in normal]
    radius_needed = BEND_MARGIN * min_bend_radius
    half = chord / 2
    largest_lift = half if half >= radius_needed else radius_needed - math.sqrt(
        radius_needed ** 2 - half ** 2)
    sagitta = min(lift, largest_lift)
    radius = (half ** 2 + sagitta ** 2) / (2 * sagitta)   # circle through a and b
    centre_offset = radius - sagitta                      # centre below the chord's middle
    middle = [(a[k] + b[k]) / 2 for k in range(3)]
    centre = [middle[k] - centre_offset * normal[k] for k in range(3)]
    half_angle = math.asin(min(1.0, half / radius))
    if sagitta > radius:  # more than a half circle (cannot happen: sagitta <= half)
        half_angle = math.pi - half_angle
    route = []
    for i in range(points):
        angle = -half_angle + 2 * half_angle * i / (points - 1)
        route.append([centre[k] + radius * (math.sin(angle) * unit[k] + math.cos(angle) * normal[k])
                      for k in range(3)])
    route[0], route[-1] = list(a), list(b)
    return route


def engine_hose(index, start, end, rng, segments):
    a, b = ENGINE_NODES[start], ENGINE_NODES[end]
    colour = [round(rng.uniform(0.05, 0.95), 3) for _ in range(3)] + [1.0]
    material = PRESET_NAMES[index % 4]
    return hose(f"hose-{index + 1}", f"{start.rsplit('/', 1)[1]} to {end.rsplit('/', 1)[1]}",
                arc_route(a, b, rng.uniform(0.08, 0.25), MIN_BEND_RADIUS[material], segments + 1),
                material,
                round(rng.uniform(0.008, 0.025), 3), colour,
                [attachment("engine", start, 0, 1), attachment("engine", end, segments - 1, segments)],
                segments=segments)


rng = random.Random(20240501)
nodes = list(ENGINE_NODES)
pairs = [(nodes[0], nodes[2]), (nodes[1], nodes[3]), (nodes[4], nodes[10]), (nodes[5], nodes[11]),
         (nodes[6], nodes[7]), (nodes[8], nodes[9])]
engine_hoses = [engine_hose(i, s, e, rng, 16) for i, (s, e) in enumerate(pairs)]
# One hose with an inline material and a rectangular cable-duct profile, free at one end.
engine_hoses.append(hose("duct-1", "cable duct", arc_route(ENGINE_NODES[nodes[7]], [0.0, 0.35, 0.3], 0.1, 0.05, 25),
                         {"expansionCoefficient": 0.03, "bendLimit": {"minBendRadius": 0.05}}, 0.03,
                         [0.1, 0.1, 0.1, 1.0], [attachment("engine", nodes[7], 0, 0)],
                         segment_length=0.02,
                         profile={"shape": "roundedRectangle", "width": 0.03, "height": 0.015,
                                  "cornerRadius": 0.004, "cornerSegments": 3}))
write("engine.ctproj", project("Two-cylinder engine with hoses", ENGINE_SCENE, engine_hoses,
                               "engine.glb"))

rng = random.Random(50)
stress = []
for i in range(50):
    start, end = rng.sample(nodes, 2)
    stress.append(engine_hose(i, start, end, rng, rng.choice([12, 16, 24, 32])))
write("engine-50-hoses.ctproj", project("Engine, 50 hoses (stress test)", ENGINE_SCENE, stress,
                                        "engine-50-hoses.glb"))

# --- test-rig: a scene this project authors itself ----------------------------------------------


def box(size):
    """24 vertices (flat normals), 36 indices of a box centred on the origin."""
    sx, sy, sz = (s / 2 for s in size)
    positions, normals, indices = [], [], []
    for axis in range(3):
        for sign in (1, -1):
            n = [0, 0, 0]
            n[axis] = sign
            u, v = [(axis + 1) % 3, (axis + 2) % 3]
            base = len(positions)
            for cu, cv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0, 0, 0]
                p[axis] = sign
                p[u] = cu
                p[v] = cv * sign
                positions.append([p[0] * sx, p[1] * sy, p[2] * sz])
                normals.append(n)
            indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return positions, normals, indices


def box_scene(scene_name, meshes_spec, nodes):
    """A glTF scene (embedded buffer) whose meshes are the boxes of `meshes_spec` (name → size)
    and whose nodes are `nodes` (mesh indices in the order of `meshes_spec`)."""
    buffer = bytearray()
    views, accessors, meshes = [], [], []
    for name, size in meshes_spec.items():
        positions, normals, indices = box(size)
        first = len(accessors)
        for data, kind, comp in ((positions, "VEC3", None), (normals, "VEC3", None)):
            offset = len(buffer)
            for p in data:
                buffer += struct.pack("<3f", *p)
            views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(buffer) - offset, "target": 34962})
            flat = list(zip(*data))
            accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(data), "type": kind,
                              "min": [min(c) for c in flat], "max": [max(c) for c in flat]})
        offset = len(buffer)
        for i in indices:
            buffer += struct.pack("<H", i)
        while len(buffer) % 4:
            buffer += b"\0"
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": 2 * len(indices), "target": 34963})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"})
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": first, "NORMAL": first + 1},
                                                     "indices": first + 2}]})
    return {
        "asset": {"version": "2.0", "generator": "ChainTube samples/generate_samples.py"},
        "scene": 0,
        "scenes": [{"name": scene_name, "nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes, "accessors": accessors, "bufferViews": views,
        "buffers": [{"byteLength": len(buffer),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(buffer)).decode()}],
    }


rig = box_scene("test-rig", {"floor_plate": (0.8, 0.01, 0.5), "bracket": (0.04, 0.2, 0.06),
                             "valve_body": (0.08, 0.06, 0.06)}, [
    {"name": "test-rig", "children": [1, 2, 3, 4]},
    {"name": "floor_plate", "mesh": 0, "translation": [0.0, 0.005, 0.0]},
    {"name": "bracket_left", "mesh": 1, "translation": [-0.3, 0.11, 0.0]},
    {"name": "bracket_right", "mesh": 1, "translation": [0.3, 0.11, 0.0]},
    {"name": "valve", "mesh": 2, "translation": [0.0, 0.04, 0.15],
     "rotation": [0.0, 0.3826834323650898, 0.0, 0.9238795325112867], "children": [5]},
    {"name": "valve_inlet", "translation": [0.04, 0.0, 0.0]},
])
(HERE / "scenes").mkdir(exist_ok=True)
(HERE / "scenes" / "test-rig.gltf").write_text(json.dumps(rig, indent=1) + "\n")

RIG_SCENE = [{"id": "rig", "path": "scenes/test-rig.gltf",
              "import": {"chordalTolerance": 0.0001, "angularTolerance": 0.5}}]
test_rig = project("Test rig: two brackets and a valve", RIG_SCENE, [
    hose("left-feed", "left bracket to valve",
         arc_route([-0.3, 0.21, 0.0], [0.0283, 0.04, 0.1217], 0.12, MIN_BEND_RADIUS["rubber hose"], 17),
         "rubber hose", 0.02, [0.1, 0.1, 0.1, 1.0],
         [attachment("rig", "/test-rig/bracket_left", 0, 1,
                     {"translation": [0.0, 0.1, 0.0], "rotation": [0.0, 0.0, 0.0, 1.0]}),
          attachment("rig", "/test-rig/valve/valve_inlet", 15, 16)], segments=16,
         fittings_allowance=0.06),
    hose("right-return", "right bracket to valve",
         arc_route([0.3, 0.21, 0.0], [0.0, 0.07, 0.15], 0.12, MIN_BEND_RADIUS["braided steel hose"], 21),
         "braided steel hose", 0.016, [0.75, 0.75, 0.78, 1.0],
         [attachment("rig", "/test-rig/bracket_right", 0, 0),
          attachment("rig", "/test-rig/valve", 20, 20)], segments=20, roughness=0.3,
         fittings_allowance=0.045),
], "test-rig.glb")
test_rig["hoses"][0]["plugs"] = {"end": "camlock-19"}  # project format 1.7: its end's plug
test_rig["sockets"] = [  # where that end may be plugged at runtime: the valve's other face, the plate
    socket("valve-outlet", "rig", "/test-rig/valve", [-0.04, 0.0, 0.0], [-1.0, 0.0, 0.0], "camlock-19"),
    socket("plate-port", "rig", "/test-rig/floor_plate", [-0.1, 0.005, -0.15], [0.0, 1.0, 0.0],
           "camlock-19"),
]
write("test-rig.ctproj", test_rig)

# --- motion-rig: a lever on a hinge and a carriage on a slider (project format 1.4 "motions") ----
motion_rig = box_scene("motion-rig", {"base_plate": (0.8, 0.01, 0.4), "pillar": (0.04, 0.2, 0.04),
                                      "lever_arm": (0.24, 0.03, 0.03), "carriage": (0.08, 0.04, 0.06)}, [
    {"name": "motion-rig", "children": [1, 2, 3, 4]},
    {"name": "base_plate", "mesh": 0, "translation": [0.0, 0.005, 0.0]},
    {"name": "pillar", "mesh": 1, "translation": [-0.3, 0.11, 0.0]},
    {"name": "lever", "mesh": 2, "translation": [0.22, 0.2, 0.0]},    # turns about z at x = 0.1
    {"name": "carriage", "mesh": 3, "translation": [0.0, 0.03, 0.15]},  # slides along x
])
(HERE / "scenes" / "motion-rig.gltf").write_text(json.dumps(motion_rig, indent=1) + "\n")
MOTION_SCENE = [{"id": "rig", "path": "scenes/motion-rig.gltf",
                 "import": {"chordalTolerance": 0.0001, "angularTolerance": 0.5}}]
motion_project = project("Motion rig: a lever on a hinge, a carriage on a slider", MOTION_SCENE, [
    hose("lever-feed", "pillar to lever tip",
         arc_route([-0.3, 0.21, 0.0], [0.3, 0.215, 0.0], 0.12, MIN_BEND_RADIUS["rubber hose"], 17),
         "rubber hose", 0.02, [0.1, 0.1, 0.1, 1.0],
         [attachment("rig", "/motion-rig/pillar", 0, 0), attachment("rig", "/motion-rig/lever", 16, 16)],
         segments=16),
    hose("carriage-feed", "pillar to carriage",
         arc_route([-0.3, 0.06, 0.02], [0.0, 0.05, 0.15], 0.1, MIN_BEND_RADIUS["cable bundle"], 17),
         "cable bundle", 0.016, [0.8, 0.3, 0.1, 1.0],
         [attachment("rig", "/motion-rig/pillar", 0, 0), attachment("rig", "/motion-rig/carriage", 16, 16)],
         segments=16),
    # A cable clamped on the base plate, straight along the slider's axis through a sliding clip
    # on the carriage's front face and a guide (a clip) on the base plate, its end free beyond
    # the guide: as the carriage slides, the side it moves away from is pulled taut and the
    # cable slides through the carriage's clip, fed from the other side.
    clip_hose("carriage-cable", "base plate through the carriage clip",
              [[x / 40, 0.03, 0.19] for x in range(-12, 13)], "cable bundle", 0.012,
              [0.15, 0.35, 0.8, 1.0], [attachment("rig", "/motion-rig/base_plate", 0, 1)],
              [clip("rig", "/motion-rig/carriage", 0.3,
                    {"translation": [0.0, 0.0, 0.04], "rotation": [0.0, 0.0, 0.0, 1.0]}),
               clip("rig", "/motion-rig/base_plate", 0.55)],
              segments=24),
], "motion-rig.glb")
motion_project["colliders"] = [{"scene": "rig", "node": "/motion-rig/base_plate"}]
motion_project["motions"] = [
    {"id": "lever", "scene": "rig", "node": "/motion-rig/lever", "kind": "hinge",
     "axis": [0.0, 0.0, 1.0], "point": [0.1, 0.2, 0.0], "min": -0.5, "max": 0.8},
    {"id": "carriage", "scene": "rig", "node": "/motion-rig/carriage", "kind": "slider",
     "axis": [1.0, 0.0, 0.0], "min": -0.05, "max": 0.05},
]
write("motion-rig.ctproj", motion_project)
print("wrote samples; now run ctproj-canonicalise on samples/*.ctproj")
