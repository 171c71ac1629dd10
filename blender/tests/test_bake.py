"""The Blender extension, headless: scenes built with bpy (5.0.1 from pip) and baked through
the operator a user clicks, `bpy.ops.hooke.bake()`.

Each bake is checked against `hooke run` of the scene it wrote (the Mesh Cache must play
Hooke's trajectory, vertices in the object's order, within 1e-6 m) and for crossings with
Blender's own BVH of the colliders' evaluated meshes, not Hooke's detection.
`cargo xtask test` runs these in `target/blender`, a Python environment of their own (bpy
pins numpy below 2), with HOOKE_BIN naming the hooke it built.
"""

import csv
import math
import os
import signal
import subprocess
import sys
import threading

import pytest

bpy = pytest.importorskip("bpy")
from mathutils import Vector  # noqa: E402
from mathutils.bvhtree import BVHTree  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
import hooke_blender  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "examples"))
from sleeve import sleeve_scene  # noqa: E402
from hooke_blender.scene import to_hooke  # noqa: E402

HOOKE = os.environ.get("HOOKE_BIN")


@pytest.fixture(autouse=True)
def fresh(tmp_path):
    """An empty scene saved in ``tmp_path`` (so that ``//hooke`` is there), the extension
    registered."""
    if not HOOKE or not os.path.isfile(HOOKE):
        pytest.skip("HOOKE_BIN does not name the hooke program")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    hooke_blender.register()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    yield tmp_path
    hooke_blender.unregister()


def activate(obj):
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)


def grid(name, size, cuts, location):
    bpy.ops.mesh.primitive_grid_add(
        x_subdivisions=cuts, y_subdivisions=cuts, size=size, location=location
    )
    obj = bpy.context.active_object
    obj.name = name
    return obj


def world_mesh(obj):
    """``obj``'s evaluated vertices (world) and faces now."""
    dg = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg)
    mesh = ev.to_mesh()
    points = [ev.matrix_world @ v.co for v in mesh.vertices]
    faces = [tuple(p.vertices) for p in mesh.polygons]
    ev.to_mesh_clear()
    return points, faces


def trajectory(scene_file):
    """`hooke run` of ``scene_file``: per frame, every vertex's position."""
    out = os.path.join(os.path.dirname(scene_file), "check.csv")
    subprocess.run(
        [HOOKE, "run", scene_file, "--trajectory", out],
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    frames = {}
    with open(out) as f:
        for row in csv.DictReader(f):
            frames.setdefault(int(row["frame"]), []).append(
                (float(row["x"]), float(row["y"]), float(row["z"]))
            )
    return frames


def assert_plays_hooke(obj, baked=None, first=0):
    """The Mesh Cache plays `hooke run`'s trajectory of the scene the bake of ``baked``
    (default: ``obj`` alone) wrote, at every frame, within 1e-6 m, ``obj``'s vertices being
    the trajectory's rows from ``first`` on; returns the frames' positions (Blender's
    world)."""
    scene = bpy.context.scene
    assert obj.modifiers.get("Hooke") is not None, [m.name for m in obj.modifiers]
    lead = hooke_blender.cache_of(baked or obj)
    expected = trajectory(os.path.splitext(lead)[0] + "-scene/scene.toml")
    played = {}
    for k, f in enumerate(range(scene.frame_start, scene.frame_end + 1)):
        scene.frame_set(f)
        points, _ = world_mesh(obj)
        played[f] = points
        want = expected[k][first : first + len(points)]
        assert len(points) == len(want)
        worst = max(
            max(abs(a - b) for a, b in zip(to_hooke(p, 1.0), w)) for p, w in zip(points, want)
        )
        assert worst < 1e-6, f"frame {f}: the cache is {worst} m from hooke run"
    return played


def crossings(cloth_points, cloth_faces, collider):
    """The cloth's vertices inside ``collider`` (its evaluated mesh now, a closed solid)
    and the cloth edges that pass through its surface, by Blender's BVH."""
    points, faces = world_mesh(collider)
    tree = BVHTree.FromPolygons(points, faces)
    inside = 0
    for p in cloth_points:
        hit = tree.find_nearest(p)
        if hit[0] is not None and (p - hit[0]).dot(hit[1]) < -1e-7:
            inside += 1
    edges = {tuple(sorted((f[i], f[(i + 1) % len(f)]))) for f in cloth_faces for i in range(len(f))}
    through = 0
    for a, b in edges:
        pa, pb = cloth_points[a], cloth_points[b]
        d = pb - pa
        hit = tree.ray_cast(pa, d.normalized(), d.length)
        if hit[0] is not None:
            through += 1
    return inside, through


def assert_never_crosses(obj, played, collider, edges=True):
    """At every frame, none of ``obj``'s played vertices is inside ``collider`` (its
    evaluated mesh then) and, with ``edges``, none of its edges passes through it."""
    scene = bpy.context.scene
    _, faces = world_mesh(obj)
    for f in range(scene.frame_start, scene.frame_end + 1):
        scene.frame_set(f)
        inside, through = crossings(played[f], faces, collider)
        assert inside == 0, f"frame {f}: {inside} of {obj.name}'s vertices in {collider.name}"
        if edges:
            assert through == 0, f"frame {f}: {through} edges through {collider.name}"


def test_a_cloth_falls_on_a_rotating_cube_and_plays_hookes_trajectory(fresh):
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 36
    scene.render.fps = 24
    cloth = grid("Cloth", 1.2, 16, (0.0, 0.0, 0.8))
    cloth.hooke.kind = "CLOTH"
    cloth.hooke.substeps = 2
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.0, 0.0, 0.4))
    cube = bpy.context.active_object
    cube.name = "Cube"
    cube.hooke.kind = "COLLIDER"
    cube.hooke.motion = "RIGID"
    cube.rotation_euler = (0.0, 0.0, 0.0)
    cube.keyframe_insert("rotation_euler", frame=1)
    cube.rotation_euler = (0.0, 0.0, math.radians(120.0))
    cube.keyframe_insert("rotation_euler", frame=36)
    activate(cloth)
    assert bpy.ops.hooke.bake() == {"FINISHED"}
    played = assert_plays_hooke(cloth)
    assert_never_crosses(cloth, played, cube)
    # It fell onto the cube: the middle rests on the top, the corners hang below it.
    top = max(p.z for p in played[scene.frame_end])
    low = min(p.z for p in played[scene.frame_end])
    assert 0.64 < top < 0.7 and low < 0.5, (top, low)


def test_a_sleeve_on_an_arm_bent_by_its_armature_never_enters_it(fresh):
    """The docs' example (blender/examples/sleeve.py): a silk sleeve pinned at its shoulder
    ring on an arm that its armature bends by 50° at the elbow and back."""
    scene = bpy.context.scene
    arm, sleeve = sleeve_scene()
    assert bpy.ops.hooke.bake() == {"FINISHED"}
    played = assert_plays_hooke(sleeve)
    assert_never_crosses(sleeve, played, arm)
    pinned = [v.index for v in sleeve.data.vertices if v.co.x < -0.44]
    for f in range(scene.frame_start, scene.frame_end + 1):
        for i in pinned:
            assert (played[f][i] - sleeve.data.vertices[i].co).length < 1e-6
    # The forearm bent down at frame 15 and the sleeve's far end went with it.
    far = [p for p in played[15] if p.x > 0.1]
    assert min(p.z for p in far) < 0.9, min(p.z for p in far)


def test_a_jelly_from_a_closed_mesh_lands_on_a_plane(fresh):
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    scene.render.fps = 24
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=0.3, location=(0.0, 0.0, 0.6))
    jelly = bpy.context.active_object
    jelly.name = "Jelly"
    jelly.hooke.kind = "JELLY"
    jelly.hooke.spacing = 0.1
    jelly.hooke.integrator = "NEWTON"
    jelly.hooke.substeps = 4
    bpy.ops.mesh.primitive_cube_add(size=3.0, location=(0.0, 0.0, -1.5))
    floor = bpy.context.active_object
    floor.name = "Floor"
    floor.hooke.kind = "COLLIDER"
    activate(jelly)
    assert bpy.ops.hooke.bake() == {"FINISHED"}
    played = assert_plays_hooke(jelly)
    assert_never_crosses(jelly, played, floor, edges=False)
    # Dropped 0.3 m from rest, it reached the floor within the second.
    assert min(p.z for p in played[scene.frame_end]) < 0.05


def edges_through(points, faces, other):
    """How many edges of the surface ``points``/``faces`` pass through ``other``'s evaluated
    mesh now, by Blender's BVH."""
    tree = BVHTree.FromPolygons(*world_mesh(other))
    edges = {tuple(sorted((f[i], f[(i + 1) % len(f)]))) for f in faces for i in range(len(f))}
    through = 0
    for a, b in edges:
        d = points[b] - points[a]
        if tree.ray_cast(points[a], d.normalized(), d.length)[0] is not None:
            through += 1
    return through


def test_bake_all_simulates_two_cloths_together_each_with_its_own_cache(fresh, capfd):
    """Two cloths dropped one onto the other, baked by one run: each plays its body's rows
    of `hooke run`'s trajectory, the upper comes to rest on the lower (baked alone, it would
    fall through it to the floor), and neither passes through the other on any frame. The
    lower one's own substeps are not read, and the bake says so."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 30
    scene.render.fps = 24
    lower = grid("Lower", 1.0, 10, (0.0, 0.0, 0.3))
    upper = grid("Upper/1", 0.6, 8, (0.05, 0.0, 0.5))
    for cloth in (lower, upper):
        cloth.hooke.kind = "CLOTH"
        cloth.hooke.friction = 0.5
    lower.hooke.substeps = 3
    bpy.ops.mesh.primitive_cube_add(size=4.0, location=(0.0, 0.0, -2.0))
    floor = bpy.context.active_object
    floor.hooke.kind = "COLLIDER"
    activate(upper)
    assert bpy.ops.hooke.bake_all() == {"FINISHED"}
    # The active one leads (its settings, the scene beside its cache); its name, with a
    # slash, cannot name a file, so its body is renamed.
    text = open(os.path.splitext(hooke_blender.cache_of(upper))[0] + "-scene/scene.toml").read()
    assert 'name = "body-0"' in text and 'name = "Lower"' in text, text
    assert "every = 1\n" in text, text
    said = capfd.readouterr()
    assert "Object 'Lower': its Integrator and Substeps (vbd, 3) are not read" in said.out + said.err
    played_upper = assert_plays_hooke(upper, upper, 0)
    played_lower = assert_plays_hooke(lower, upper, len(upper.data.vertices))
    _, upper_faces = world_mesh(upper)
    _, lower_faces = world_mesh(lower)
    for f in range(scene.frame_start, scene.frame_end + 1):
        scene.frame_set(f)
        assert edges_through(played_upper[f], upper_faces, lower) == 0, f
        assert edges_through(played_lower[f], lower_faces, upper) == 0, f
    end = scene.frame_end
    mean = lambda points: sum(p.z for p in points) / len(points)  # noqa: E731
    gap = mean(played_upper[end]) - mean(played_lower[end])
    assert mean(played_lower[end]) < 0.02 and 0.003 < gap < 0.02, (mean(played_lower[end]), gap)
    # Free All removes both bakes.
    assert bpy.ops.hooke.free_all() == {"FINISHED"}
    for cloth in (lower, upper):
        assert cloth.modifiers.get("Hooke") is None
        assert not os.path.exists(hooke_blender.cache_of(cloth))


def test_what_hooke_warns_of_in_a_bake_that_finishes_is_reported(fresh, capfd):
    """A cloth laid 2 mm above a cube's top at the first frame, nearer than its 5 mm
    thickness, is moved out before the first step, and the run warns of it: the bake
    finishes and plays, and Blender's report says what hooke said, naming the object."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 3
    cloth = grid("Cloth", 1.0, 6, (0.0, 0.0, 0.252))
    cloth.hooke.kind = "CLOTH"
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.0, 0.0, 0.0))
    bpy.context.active_object.hooke.kind = "COLLIDER"
    activate(cloth)
    assert bpy.ops.hooke.bake() == {"FINISHED"}
    said = capfd.readouterr()
    text = said.out + said.err
    assert "Object 'Cloth': hooke warns:" in text and "started inside collider" in text, text
    assert_plays_hooke(cloth)


def test_bad_settings_are_refused_naming_the_object_and_the_setting(fresh):
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 5
    cloth = grid("Cloth", 1.0, 4, (0.0, 0.0, 1.0))
    activate(cloth)
    with pytest.raises(RuntimeError, match=r"Scene 'Scene': no object is a cloth or a jelly"):
        bpy.ops.hooke.bake_all()
    cloth.hooke.kind = "CLOTH"
    cloth.hooke.pin_group = "hem"
    with pytest.raises(RuntimeError, match=r"Object 'Cloth': vertex group 'hem' does not exist"):
        bpy.ops.hooke.bake()
    with pytest.raises(RuntimeError, match=r"Object 'Cloth': vertex group 'hem' does not exist"):
        bpy.ops.hooke.bake_all()
    cloth.hooke.pin_group = ""
    bpy.ops.mesh.primitive_circle_add(vertices=8, radius=0.3, fill_type="NOTHING")
    ring = bpy.context.active_object
    ring.name = "Ring"
    ring.hooke.kind = "COLLIDER"
    activate(cloth)
    with pytest.raises(RuntimeError, match=r"Object 'Ring': it has no faces"):
        bpy.ops.hooke.bake()
    bpy.data.objects.remove(ring)
    # A deforming collider whose modifier changes its faces from frame to frame.
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.2, location=(0.0, 0.0, 0.3))
    ball = bpy.context.active_object
    ball.name = "Ball"
    ball.hooke.kind = "COLLIDER"
    ball.hooke.motion = "DEFORMING"
    build = ball.modifiers.new("build", "BUILD")
    build.frame_start, build.frame_duration = 1, 4
    activate(cloth)
    with pytest.raises(RuntimeError, match=r"Object 'Ball': its mesh changes topology at frame 2"):
        bpy.ops.hooke.bake()


def baked_cloth():
    """A small cloth baked over 12 frames, and its cache's bytes."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 12
    cloth = grid("Cloth", 1.0, 10, (0.0, 0.0, 1.0))
    cloth.hooke.kind = "CLOTH"
    activate(cloth)
    assert bpy.ops.hooke.bake() == {"FINISHED"}
    cache = hooke_blender.cache_of(cloth)
    return cloth, cache, open(cache, "rb").read()


def assert_earlier_bake_plays(cloth, cache, before):
    """After a cancelled bake: the earlier cache byte for byte, still played, no work
    folder left; then free bake removes it."""
    assert open(cache, "rb").read() == before
    assert cloth.modifiers["Hooke"].filepath == cache
    folder = os.path.dirname(cache)
    assert [n for n in os.listdir(folder) if n.startswith(".bake-") or n.endswith(".part")] == []
    bpy.context.scene.frame_end = 12
    assert_plays_hooke(cloth)
    assert bpy.ops.hooke.free_bake() == {"FINISHED"}
    assert cloth.modifiers.get("Hooke") is None and not os.path.exists(cache)


def test_a_bake_interrupted_while_hooke_runs_keeps_the_earlier_cache_playing(fresh):
    cloth, cache, before = baked_cloth()
    # A bake far longer than the wait below (2000 frames of 400 steps each), interrupted
    # as Ctrl-C interrupts `blender --background`: once hooke runs and streams its export
    # (its hidden temporary file is there; the export appears only once hooke ends).
    bpy.context.scene.frame_end = 2000
    cloth.hooke.integrator = "SYMPLECTIC"
    cloth.hooke.substeps = 400
    folder = os.path.dirname(cache)
    stop = threading.Event()

    def streaming():
        for run in (n for n in os.listdir(folder) if n.startswith(".bake-")):
            names = os.listdir(os.path.join(folder, run))
            if any(n.startswith(".hooke-") and n.endswith(".tmp") for n in names):
                return True
        return False

    def interrupt():
        while not stop.wait(0.02):
            if streaming():
                os.kill(os.getpid(), signal.SIGINT)
                return

    # Ctrl-C raises KeyboardInterrupt as in a terminal, even where the tests were started
    # with SIGINT ignored (a background job of a non-interactive shell), where it failed.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    watcher = threading.Thread(target=interrupt, daemon=True)
    watcher.start()
    try:
        assert bpy.ops.hooke.bake() == {"CANCELLED"}
    finally:
        stop.set()
        watcher.join()
        signal.signal(signal.SIGINT, previous)
    assert_earlier_bake_plays(cloth, cache, before)


def test_a_bake_interrupted_while_its_cache_is_read_keeps_the_earlier_cache(fresh, monkeypatch):
    # hooke has finished and the add-on reads its export when Ctrl-C comes (the race a
    # fast machine meets): still a cancel, not an error, and nothing of the new bake stays.
    cloth, cache, before = baked_cloth()
    cloth.hooke.substeps = 2
    read = hooke_blender.pc2.read

    def interrupted(path):
        read(path)
        raise KeyboardInterrupt

    monkeypatch.setattr(hooke_blender.pc2, "read", interrupted)
    assert bpy.ops.hooke.bake() == {"CANCELLED"}
    monkeypatch.setattr(hooke_blender.pc2, "read", read)
    cloth.hooke.substeps = 1
    assert_earlier_bake_plays(cloth, cache, before)


INSTALLED = r"""
import os, sys, bpy
zip_path, hooke = sys.argv[-2], sys.argv[-1]
bpy.ops.wm.read_factory_settings(use_empty=True)
assert bpy.ops.extensions.package_install_files(
    filepath=zip_path, repo="user_default", enable_on_install=True
) == {"FINISHED"}
prefs = bpy.context.preferences.addons["bl_ext.user_default.hooke"].preferences
prefs.program = hooke
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 6
bpy.ops.mesh.primitive_grid_add(x_subdivisions=6, y_subdivisions=6, size=1.0, location=(0, 0, 1))
cloth = bpy.context.active_object
cloth.hooke.kind = "CLOTH"
assert bpy.ops.hooke.bake() == {"FINISHED"}
assert cloth.modifiers["Hooke"].type == "MESH_CACHE"
scene.frame_set(6)
dg = bpy.context.evaluated_depsgraph_get()
low = min((cloth.matrix_world @ v.co).z for v in cloth.evaluated_get(dg).to_mesh().vertices)
print("LOWEST", low)
"""


def test_the_zip_installs_as_an_extension_and_bakes(tmp_path):
    """The zip `blender/build.py` makes, installed through Blender's own Install from Disk
    (in a fresh user folder, in a Blender of its own), registers the panel's settings and
    the operator, finds hooke through its preference, and bakes a falling cloth."""
    build = os.path.join(os.path.dirname(__file__), "..", "build.py")
    out = subprocess.run(
        [sys.executable, build, "--out", str(tmp_path)], check=True, capture_output=True, text=True
    )
    zip_path = out.stdout.strip()
    script = tmp_path / "installed.py"
    script.write_text(INSTALLED)
    home = tmp_path / "home"
    home.mkdir()
    env = dict(os.environ, HOME=str(home), BLENDER_USER_RESOURCES=str(home / "blender"))
    env.pop("HOOKE_BIN", None)
    done = subprocess.run(
        [sys.executable, str(script), zip_path, HOOKE],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    lowest = float(done.stdout.split("LOWEST")[1].split()[0])
    # Five implicit Euler steps of 1/24 s from rest fall g dt² (1 + … + 5) = 25.5 cm (the
    # continuous ½ g t² is 21.3 cm); the cloth's air drag takes a little off.
    assert 0.74 < lowest < 0.76, lowest
