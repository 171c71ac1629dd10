"""Times Blender's cloth on the draping 128² tablecloth (benches/scenes/tablecloth-128-drape.toml):
the same grid (128 x 128 vertices, 1.6 m square, 1.3 m up), the same round table
(assets/meshes/table.obj) and ground, 3 s at 60 frames a second, Blender's default cloth
quality (5 steps a frame) and self-collision on (at Hooke's thickness), the same 0.4 kg and the same drag per
unit mass (1.25e-4 N·s/m over 2.44e-5 kg = 5.12 /s). Blender is Z-up: Hooke's (x, y, z) is
Blender's (x, -z, y).

    python benches/blender/cloth_128.py [SECONDS] [N]

Prints one JSON line: Blender's version, the wall seconds of the bake and per simulated
second, the cloth's lowest and mean height at the end (metres, Hooke's y). Needs `bpy`
(`pip install bpy`, Python 3.11); not part of the test suite.
"""

import json
import os
import sys
import time

import bpy

seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 3.0
n = int(sys.argv[2]) if len(sys.argv) > 2 else 128
here = os.path.dirname(os.path.abspath(__file__))
table = os.path.join(here, "..", "..", "assets", "meshes", "table.obj")

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 60
frames = round(seconds * 60)
scene.frame_start = 1
scene.frame_end = frames + 1

# The cloth: n x n vertices 0.0126 m apart (1.6 m square), its corner at Hooke's
# (-0.8, 1.3, -0.8).
spacing = 1.6 / (n - 1)
verts = [(-0.8 + i * spacing, 0.8 - j * spacing, 1.3) for j in range(n) for i in range(n)]
faces = []
for j in range(n - 1):
    for i in range(n - 1):
        a = j * n + i
        faces.append((a, a + 1, a + n + 1, a + n))
mesh = bpy.data.meshes.new("cloth")
mesh.from_pydata(verts, [], faces)
cloth = bpy.data.objects.new("cloth", mesh)
scene.collection.objects.link(cloth)
mod = cloth.modifiers.new("Cloth", "CLOTH")
settings = mod.settings
settings.quality = 5
# Per vertex: the scene's 0.4 kg cloth spread over the vertices, and its drag per unit
# mass (Blender's air force is -air_damping v on each vertex, as Hooke's drag).
settings.mass = 0.4 / (n * n)
settings.air_damping = 5.12 * settings.mass
# Hooke's thickness on this cloth is a quarter of the spacing (3.15 mm at 128²); Blender's
# default distances (15 mm) exceed the spacing itself, so every neighbour would collide.
collision = mod.collision_settings
collision.use_self_collision = True
collision.distance_min = 0.25 * spacing
collision.self_distance_min = 0.25 * spacing
cache = mod.point_cache
cache.frame_start = 1
cache.frame_end = frames + 1

# The table (Y-up OBJ, turned to Z-up) and the ground, as collision objects.
bpy.ops.wm.obj_import(filepath=table, forward_axis="NEGATIVE_Z", up_axis="Y")
for obj in bpy.context.selected_objects:
    obj.modifiers.new("Collision", "COLLISION")
bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, 0.0))
bpy.context.active_object.modifiers.new("Collision", "COLLISION")

start = time.perf_counter()
for frame in range(1, frames + 2):
    scene.frame_set(frame)
    if frame % 30 == 0:
        print(f"frame {frame} of {frames + 1}: {time.perf_counter() - start:.1f} s", file=sys.stderr)
wall = time.perf_counter() - start

evaluated = cloth.evaluated_get(bpy.context.evaluated_depsgraph_get())
heights = [(evaluated.matrix_world @ v.co).z for v in evaluated.data.vertices]
print(
    json.dumps(
        {
            "blender": bpy.app.version_string,
            "n": n,
            "simulated_s": seconds,
            "wall_s": wall,
            "wall_per_simulated_s": wall / seconds,
            "lowest_y": min(heights),
            "mean_y": sum(heights) / len(heights),
        }
    )
)
