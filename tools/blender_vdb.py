# Checks that Blender imports a hairpipe VDB sequence as a volume, headless:
#
#   blender -b --python tools/blender_vdb.py -- out/default/vdb [preview.png]
#
# Prints, per frame, the file Blender loaded, its grids (name, type) and the
# volume's world bounds; with a PNG path also renders frame 1 with Cycles on
# the CPU (the B-render camera and light, hair-like brown volume). Not used by
# the tests (Blender is an optional, large package).
#
# hairpipe writes a Y-up world; Blender is Z-up, so the object is turned +90°
# about X (hairpipe (x, y, z) is Blender (x, -z, y)). The density grid holds
# hair volume fraction; the volume shader's Density ≈ 1 / (2 r) turns it into
# extinction for fibres of radius r (20000 /m for r = 25 µm).
import math
import os
import sys

import bpy
import mathutils

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not args:
    sys.exit("usage: blender -b --python tools/blender_vdb.py -- VDB_FOLDER [render.png]")
folder = os.path.abspath(args[0])
files = sorted(f for f in os.listdir(folder) if f.endswith(".vdb"))
if not files:
    sys.exit(f"no .vdb files in {folder}")

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.object.volume_import(filepath=os.path.join(folder, files[0]), directory=folder,
                             files=[{"name": f} for f in files], use_sequence_detection=True)
obj = bpy.context.selected_objects[0]
obj.rotation_euler = (math.radians(90), 0, 0)
volume = obj.data
print(f"VOLUME {obj.name}: sequence {volume.is_sequence}, {volume.frame_duration} frames from {volume.frame_start}")

scene = bpy.context.scene
failures = 0
for frame in range(volume.frame_start, volume.frame_start + max(1, volume.frame_duration)):
    scene.frame_set(frame)
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    grids = evaluated.data.grids
    if not grids.load():
        failures += 1
        print(f"FRAME {frame}: cannot load {grids.frame_filepath}: {grids.error_message}")
        continue
    corners = [evaluated.matrix_world @ mathutils.Vector(c) for c in evaluated.bound_box]
    lo = [round(min(c[i] for c in corners), 4) for i in range(3)]
    hi = [round(max(c[i] for c in corners), 4) for i in range(3)]
    names = ", ".join(f"{g.name} ({g.data_type})" for g in grids)
    print(f"FRAME {frame}: {os.path.basename(grids.frame_filepath)}: grids {names}; bounds {lo} .. {hi}")

if len(args) > 1:
    material = bpy.data.materials.new("hair")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.clear()
    shader = nodes.new("ShaderNodeVolumePrincipled")
    shader.inputs["Density"].default_value = 20000.0
    shader.inputs["Color"].default_value = (0.35, 0.22, 0.12, 1)
    output = nodes.new("ShaderNodeOutputMaterial")
    material.node_tree.links.new(shader.outputs[0], output.inputs["Volume"])
    volume.materials.append(material)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    camera.location = (0, -0.9, 0.05)  # hairpipe (0, 0.05, 0.9)
    camera.data.sensor_fit = 'VERTICAL'
    camera.data.angle_y = math.radians(40)
    camera.rotation_euler = mathutils.Vector((0, 0.9, -0.05)).to_track_quat('-Z', 'Y').to_euler()
    scene.camera = camera
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.data.energy = 3.0
    sun.rotation_euler = mathutils.Vector((-1, 1, -1)).to_track_quat('-Z', 'Y').to_euler()  # hairpipe (-1, -1, -1)
    scene.world = bpy.data.worlds.new("world")
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = 16
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = 480, 270
    scene.render.filepath = os.path.abspath(args[1])
    scene.frame_set(volume.frame_start)
    bpy.ops.render.render(write_still=True)
    print(f"RENDERED {scene.render.filepath}")

sys.exit(1 if failures else 0)
