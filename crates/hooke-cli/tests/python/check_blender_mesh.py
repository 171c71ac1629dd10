"""A mesh body the way a Blender user meets it (bpy from PyPI: `pip install bpy numpy`): Blender
makes and exports an OBJ with quads, triangles, an 8-sided face, a hole and a UV seam at
every face (lightmap pack); Hooke drapes it and writes a PC2; Blender imports the *same*
OBJ, adds a Mesh Cache modifier with Hooke's PC2, and the vertices it shows are compared
with Hooke's trajectory (a row per vertex of the file). Not part of the test suite (bpy is
a large download); run by hand:

    python check_blender_mesh.py make sheet.obj
    python check_blender_mesh.py make-sleeve sleeve.obj   # tests/fixtures/blender-sleeve.obj
    hooke run sheet.toml --export run.pc2 --trajectory run.csv   # sheet.toml: docs/output.md
    python check_blender_mesh.py play sheet.obj run.pc2 run.csv

Blender is Z-up, so Hooke's (x, y, z) is expected at (x, -z, y).
"""

import csv
import sys

import bpy  # noqa: I001 (bpy first: it makes bmesh and mathutils importable)
import bmesh
import numpy as np
from mathutils import Vector


def make(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=24, y_subdivisions=24, size=1.0)
    me = bpy.context.active_object.data
    bm = bmesh.new()
    bm.from_mesh(me)
    hole = [f for f in bm.faces if (f.calc_center_median() - Vector((0.2, 0.1, 0))).length < 0.12]
    bmesh.ops.delete(bm, geom=hole, context="FACES")
    block = [
        f
        for f in bm.faces
        if abs(f.calc_center_median().x + 0.25) < 0.045 and abs(f.calc_center_median().y + 0.25) < 0.045
    ]
    bmesh.ops.dissolve_faces(bm, faces=block)
    bmesh.ops.triangulate(bm, faces=[f for f in bm.faces if f.calc_center_median().x > 0.35])
    bm.to_mesh(me)
    bm.free()
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.uv.lightmap_pack()
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.wm.obj_export(filepath=path, export_uv=True, export_normals=False, export_materials=False)


def make_sleeve(path):
    """An open cylinder as a Blender user makes a sleeve: 12 cm across, 60 cm long, its axis
    along x, 56 cm above the ground, 32 sides cut into 12 rings, triangulated (Beauty)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_cylinder_add(
        vertices=32, radius=0.06, depth=0.6, end_fill_type="NOTHING", rotation=(0, 1.5707963, 0), location=(0, 0, 0.56)
    )
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)
    me = bpy.context.active_object.data
    bm = bmesh.new()
    bm.from_mesh(me)
    along = [e for e in bm.edges if abs(e.verts[0].co.x - e.verts[1].co.x) > 0.3]
    bmesh.ops.subdivide_edges(bm, edges=along, cuts=11, use_grid_fill=True)
    bmesh.ops.triangulate(bm, faces=bm.faces[:], quad_method="BEAUTY")
    bm.to_mesh(me)
    bm.free()
    bpy.ops.wm.obj_export(filepath=path, export_uv=False, export_normals=False, export_materials=False)


def play(obj_path, pc2, traj):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.obj_import(filepath=obj_path)
    obj = bpy.context.selected_objects[0]
    mod = obj.modifiers.new("cache", "MESH_CACHE")
    mod.cache_format = "PC2"
    mod.filepath = pc2
    mod.frame_start = 1
    rows = {}
    with open(traj, newline="") as f:
        for r in csv.DictReader(f):
            rows.setdefault(int(r["frame"]), []).append([float(r[k]) for k in ("x", "y", "z")])
    worst = 0.0
    for frame in sorted(rows)[:: max(1, len(rows) // 5)] + [max(rows)]:
        bpy.context.scene.frame_set(frame + 1)
        ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        got = np.array([tuple(ev.matrix_world @ v.co) for v in ev.to_mesh().vertices])
        want = np.array(rows[frame])
        want = np.stack([want[:, 0], -want[:, 2], want[:, 1]], axis=1)
        assert got.shape == want.shape, (got.shape, want.shape)
        worst = max(worst, np.abs(got - want).max())
    print(f"{len(got)} vertices, largest difference {worst:.2e} m")
    assert worst < 1e-6


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    {"make": make, "make-sleeve": make_sleeve, "play": play}[args[0]](*args[1:])
