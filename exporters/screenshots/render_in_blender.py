# Renders an exported hose rig as Blender imports it (the picture in the top-level README):
#   chaintube export samples/test-rig.ctproj -o /tmp/test-rig.glb
#   blender -b --factory-startup --python exporters/screenshots/render_in_blender.py -- \
#       /tmp/test-rig.glb exporters/screenshots/test-rig-in-blender.png
# Cycles on the CPU (no display needed), a camera framing everything from the front right.
import math
import sys

import numpy  # Blender 3.4's glTF importer uses numpy.bool, removed in numpy >= 1.24
if not hasattr(numpy, "bool"):
    numpy.bool = bool
import bpy
from mathutils import Vector

source, target = sys.argv[sys.argv.index("--") + 1:][:2]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=source)

meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
bpy.context.view_layer.update()
corners = []
for o in meshes:
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = o.evaluated_get(depsgraph)
    corners += [evaluated.matrix_world @ Vector(c) for c in evaluated.bound_box]
low = Vector([min(c[i] for c in corners) for i in range(3)])
high = Vector([max(c[i] for c in corners) for i in range(3)])
centre, size = (low + high) / 2, (high - low).length

camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
bpy.context.scene.collection.objects.link(camera)
direction = Vector((0.55, 0.45, 0.85)).normalized()  # Blender is +Z up
camera.location = centre + direction * size * 1.2
camera.rotation_euler = (centre - camera.location).to_track_quat("-Z", "Y").to_euler()
camera.data.lens = 45
bpy.context.scene.camera = camera

sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.data.energy = 3.0
sun.rotation_euler = (math.radians(40), math.radians(10), math.radians(30))
bpy.context.scene.collection.objects.link(sun)
world = bpy.data.worlds.new("world")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (0.32, 0.34, 0.38, 1)
world.node_tree.nodes["Background"].inputs[1].default_value = 0.8
bpy.context.scene.world = world

scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 64
scene.cycles.use_denoising = False
scene.render.threads_mode = "FIXED"
scene.render.threads = 1
scene.render.resolution_x, scene.render.resolution_y = 720, 405
scene.render.filepath = target
scene.render.image_settings.color_mode = "RGB"
bpy.ops.render.render(write_still=True)
