"""Reads Hooke's exports with other people's readers and compares them with the run's
trajectory CSV (docs/physics.md §6), frame by frame.

    check_export.py usd STAGE.usda TRAJECTORY.csv FPS
    check_export.py pc2 CACHE.pc2 TRAJECTORY.csv FIRST_PARTICLE

USD is read with Pixar's own module (usd-core from PyPI); the point cache with the layout
Blender's Mesh Cache modifier reads. Positions and velocities must be the float32 nearest
the trajectory's float64 values. Prints one line of figures; exits non-zero on a mismatch.
"""

import csv
import struct
import sys

import numpy as np


def trajectory(path):
    """Positions and velocities per frame: arrays (frames, particles, 3)."""
    rows = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            rows.setdefault(int(r["frame"]), []).append(
                (int(r["particle"]), [float(r[k]) for k in ("x", "y", "z", "vx", "vy", "vz")])
            )
    frames = sorted(rows)
    assert frames == list(range(len(frames))), "frames are numbered 0, 1, …"
    data = np.array([[v for _, v in sorted(rows[f])] for f in frames])
    return data[:, :, :3], data[:, :, 3:]


def fail(message):
    print("MISMATCH: " + message)
    sys.exit(1)


def check_usd(stage_path, csv_path, fps):
    from pxr import Usd, UsdGeom

    x, v = trajectory(csv_path)
    stage = Usd.Stage.Open(stage_path)
    if stage is None:
        fail("usd-core cannot open the stage")
    if UsdGeom.GetStageUpAxis(stage) != UsdGeom.Tokens.y:
        fail("up axis is not Y")
    if UsdGeom.GetStageMetersPerUnit(stage) != 1.0:
        fail("metres per unit is not 1")
    frames = x.shape[0]
    if (stage.GetStartTimeCode(), stage.GetEndTimeCode()) != (0, frames - 1):
        fail(f"time codes {stage.GetStartTimeCode()}..{stage.GetEndTimeCode()}, frames {frames}")
    if abs(stage.GetTimeCodesPerSecond() - fps) > 1e-9 * fps:
        fail(f"timeCodesPerSecond {stage.GetTimeCodesPerSecond()}, expected {fps}")
    world = stage.GetDefaultPrim()
    offset, kinds, compared = 0, [], 0
    for prim in world.GetChildren():
        if prim.GetName() == "colliders":
            for c in prim.GetChildren():
                mesh = UsdGeom.Mesh(c)
                counts = mesh.GetFaceVertexCountsAttr().Get()
                if sum(counts) != len(mesh.GetFaceVertexIndicesAttr().Get()):
                    fail(f"collider {c.GetName()}: counts and indices disagree")
            continue
        kinds.append(prim.GetTypeName())
        geom = UsdGeom.PointBased(prim)
        points, velocities = geom.GetPointsAttr(), geom.GetVelocitiesAttr()
        n = len(points.Get(0))
        if prim.IsA(UsdGeom.Mesh):
            mesh = UsdGeom.Mesh(prim)
            counts = mesh.GetFaceVertexCountsAttr().Get()
            indices = np.array(mesh.GetFaceVertexIndicesAttr().Get())
            if sum(counts) != len(indices) or indices.max() >= n or indices.min() < 0:
                fail(f"{prim.GetName()}: topology does not fit its {n} points")
        if points.GetTimeSamples() != list(range(frames)):
            fail(f"{prim.GetName()}: points sampled at {points.GetTimeSamples()[:5]}…")
        for t in range(frames):
            for attr, want in ((points, x), (velocities, v)):
                got = np.array(attr.Get(t), dtype=np.float32)
                expected = want[t, offset : offset + n].astype(np.float32)
                if got.shape != expected.shape or not np.array_equal(got, expected):
                    bad = np.argwhere(got != expected)[:1]
                    fail(f"{prim.GetName()}.{attr.GetName()} at time code {t}: first difference {bad}")
                compared += got.size
            lo, hi = np.array(geom.GetExtentAttr().Get(t))
            if (x[t, offset : offset + n] < lo).any() or (x[t, offset : offset + n] > hi).any():
                fail(f"{prim.GetName()}: extent at {t} does not hold every point")
        offset += n
    if offset != x.shape[1]:
        fail(f"the stage holds {offset} points, the trajectory {x.shape[1]} particles")
    print(f"usd: {frames} time codes, prims {kinds}, {compared} values equal")


def check_pc2(cache_path, csv_path, first):
    x, _ = trajectory(csv_path)
    with open(cache_path, "rb") as f:
        data = f.read()
    magic, version, points, start, sampling, samples = struct.unpack("<12siiffi", data[:32])
    if magic != b"POINTCACHE2\0" or version != 1:
        fail(f"header {magic!r} version {version}")
    if (start, sampling) != (0.0, 1.0):
        fail(f"start {start} sampling {sampling}")
    if samples != x.shape[0]:
        fail(f"{samples} samples, {x.shape[0]} frames")
    if len(data) != 32 + samples * points * 12:
        fail(f"{len(data)} bytes for {samples} samples of {points} points")
    cache = np.frombuffer(data[32:], dtype="<f4").reshape(samples, points, 3)
    expected = x[:, first : first + points].astype(np.float32)
    if not np.array_equal(cache, expected):
        fail(f"first difference at {np.argwhere(cache != expected)[:1]}")
    print(f"pc2: {samples} samples of {points} points equal")


if __name__ == "__main__":
    kind, path, trajectory_csv, extra = sys.argv[1:5]
    if kind == "usd":
        check_usd(path, trajectory_csv, float(extra))
    elif kind == "pc2":
        check_pc2(path, trajectory_csv, int(extra))
    else:
        sys.exit(f"unknown check {kind}")
