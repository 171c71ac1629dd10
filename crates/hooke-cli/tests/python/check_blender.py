"""Opens Hooke's exports in Blender (its `bpy` module: `pip install bpy==4.2.0`, Python 3.11)
the way the README tells a user to, and compares what Blender shows with the trajectory.

    python check_blender.py usd STAGE.usda TRAJECTORY.csv
    python check_blender.py pc2 CACHE.pc2 TRAJECTORY.csv

USD: File → Import → USD; the body meshes at several frames. PC2: File → Import → OBJ with
its defaults, a Mesh Cache modifier with Frame Start 1. Blender is Z-up, so Hooke's
(x, y, z) is expected at (x, -z, y). Not part of the test suite (bpy is large); run by hand.
"""

import csv
import sys

import bpy
import numpy as np


def trajectory(path):
    rows = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            rows.setdefault(int(r["frame"]), []).append([float(r[k]) for k in ("x", "y", "z")])
    return rows


def world(obj, scene, frame):
    scene.frame_set(frame)
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    m = evaluated.matrix_world
    return np.array([tuple(m @ v.co) for v in evaluated.to_mesh().vertices])


def z_up(x):
    x = np.array(x)
    return np.stack([x[:, 0], -x[:, 2], x[:, 1]], axis=1)


def main(kind, path, csv_path):
    rows = trajectory(csv_path)
    last = max(rows)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    worst = 0.0
    if kind == "usd":
        bpy.ops.wm.usd_import(filepath=path)
        # Bodies in the stage's order; the colliders sit under /World/colliders.
        bodies = [
            o
            for o in bpy.data.objects
            if o.type == "MESH" and not (o.parent and o.parent.name == "colliders")
        ]
        # Blender lists objects by name, not in the stage's order: one body keeps the
        # mapping to particles plain.
        if len(bodies) != 1:
            sys.exit(f"expected one body mesh, Blender imported {[o.name for o in bodies]}")
        offset = 0
        for obj in bodies:
            n = len(obj.data.vertices)
            for f in (0, last // 2, last):
                got = world(obj, scene, f)
                worst = max(worst, np.abs(got - z_up(rows[f][offset : offset + n])).max())
            offset += n
    elif kind == "pc2":
        bpy.ops.wm.obj_import(filepath=path[: -len(".pc2")] + ".obj")
        obj = [o for o in bpy.data.objects if o.type == "MESH"][0]
        cache = obj.modifiers.new("cache", "MESH_CACHE")
        cache.cache_format = "PC2"
        cache.filepath = path
        cache.frame_start = 1
        n = len(obj.data.vertices)
        for f in (0, last // 2, last):
            got = world(obj, scene, f + 1)
            worst = max(worst, np.abs(got - z_up(rows[f][:n])).max())
    else:
        sys.exit(f"unknown check {kind}")
    print(f"blender {kind}: largest difference {worst:.3g} m")
    sys.exit(0 if worst < 1e-5 else 1)


if __name__ == "__main__":
    main(*sys.argv[1:4])
