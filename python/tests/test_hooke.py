"""The `hooke` Python package as a notebook user drives it: same bits as the command, numpy
arrays, errors with their file and line, renders, exports, Ctrl-C, the GIL released while
stepping, and sweeps whose results do not depend on where they ran (serial, a process
pool, a local Ray cluster).

Needs the `hooke` command for the bit-for-bit comparison: `HOOKE_BIN`, as `cargo xtask test`
sets it, or `hooke` on the PATH.
"""

import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import hooke

ROOT = Path(__file__).resolve().parents[2]


def hooke_bin():
    path = os.environ.get("HOOKE_BIN") or shutil.which("hooke")
    assert path, "set HOOKE_BIN to the hooke command (cargo xtask test does) or put it on PATH"
    return path


def cli_trajectory(tmp_path, *args):
    """`hooke run ARGS --trajectory t.csv`: positions and velocities per frame."""
    out = tmp_path / "t.csv"
    subprocess.run([hooke_bin(), "run", *args, "--trajectory", str(out)], check=True,
                   capture_output=True)
    frames = {}
    with open(out, newline="") as f:
        for r in csv.DictReader(f):
            frames.setdefault(int(r["frame"]), []).append(
                [float(r[k]) for k in ("x", "y", "z", "vx", "vy", "vz")])
    return [np.array(frames[k]) for k in sorted(frames)]


@pytest.mark.parametrize("source, steps, every", [
    ("chain", 2000, 100),
    ("cloth-table", 1200, 40),            # contacts: sticking to the mesh table
    ("assets/worlds/rotate.w", 300, 10),  # rk4, force field, penalty colliders
    ("flag", 800, 40),                    # air
    ("cloth-pile", 30, 5),                # block descent at a 60 Hz frame (with --dt below)
])
def test_a_trajectory_stepped_from_python_is_the_commands_bit_for_bit(tmp_path, source, steps, every):
    path = str(ROOT / source) if source.endswith(".w") else source
    large = {"integrator": "vbd", "dt": 1 / 60} if source == "cloth-pile" else {}
    flags = [a for k, v in large.items() for a in (f"--{k}", str(v))]
    frames = cli_trajectory(tmp_path, path, "--steps", str(steps), "--every", str(every), *flags)
    sim = hooke.load(path, steps=steps, every=every, **large)
    assert sim.integrator == large.get("integrator", sim.integrator)
    for k, expected in enumerate(frames):
        if k > 0:
            sim.step(every)
        got = np.hstack([sim.positions, sim.velocities])
        # The CSV holds each number's shortest round-trip digits: equal means same bits.
        assert np.array_equal(got, expected), f"{source}: frame {k} differs"
    assert sim.steps_taken == steps


def test_arrays_have_the_documented_shapes_and_cannot_be_written():
    sim = hooke.load("hanging-cloth")
    x, v, m, springs = sim.positions, sim.velocities, sim.masses, sim.springs
    assert x.shape == v.shape == (625, 3) and x.dtype == np.float64
    assert m.shape == (625,) and abs(m.sum() - 0.5) < 1e-12
    assert springs.shape == (len(springs), 2) and springs.dtype == np.int64
    assert springs.min() >= 0 and springs.max() < 625
    assert sim.pinned.sum() == 2
    assert sim.bodies == [("cloth", 0, 625)]
    with pytest.raises(ValueError):
        x[0, 0] = 1.0
    # A copy of the state at the time it was taken.
    before = sim.positions
    sim.step(100)
    assert not np.array_equal(before, sim.positions)
    assert sim.time == pytest.approx(100 * sim.dt)


def test_advance_takes_the_nearest_whole_number_of_steps():
    sim = hooke.load("chain")
    sim.advance(10.4 * sim.dt)
    assert sim.steps_taken == 10
    sim.run()
    assert sim.steps_taken == sim.total_steps
    with pytest.raises(ValueError):
        sim.advance(-1.0)
    with pytest.raises(ValueError, match="more than the 1e12 a call may take"):
        sim.advance(1e300)


def test_steps_ended_at_the_large_steps_budget_are_counted():
    starved = hooke.load("hanging-cloth", integrator="vbd", dt=1 / 60, iterations=1)
    starved.step(6)
    assert starved.unsolved_steps == 6
    fed = hooke.load("hanging-cloth", integrator="vbd", dt=1 / 60, iterations=5000,
                     tolerance=0.5)
    fed.step(6)
    assert fed.unsolved_steps == 0
    explicit = hooke.load("hanging-cloth")
    explicit.step(6)
    assert explicit.unsolved_steps == 0


def test_bad_input_raises_with_the_file_line_or_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\n[simulation]\nintegrator = "rk5"\ndt = 0.001\nsteps = 10\nevery = 1\n')
    with pytest.raises(hooke.HookeError, match=r"bad.toml: line 3, column 14: unknown integrator 'rk5'"):
        hooke.load(str(bad))
    with pytest.raises(hooke.HookeError, match="no built-in scene 'nope'"):
        hooke.load("nope")
    with pytest.raises(hooke.HookeError, match="dt: expected a finite number of seconds > 0"):
        hooke.load("chain", dt=-1.0)
    with pytest.raises(hooke.HookeError, match="springz"):
        hooke.load("hanging-cloth", set={"body.springz.ks": 1.0})
    with pytest.raises(hooke.HookeError, match="table nope.obj: no such file"):
        hooke.load("cloth-table", table="nope.obj")
    with pytest.raises(TypeError):
        hooke.load("chain", stiffness=3)
    with pytest.raises(hooke.DivergenceError, match=r"diverged at step \d+ .* use dt = "):
        hooke.load("chain", dt=10.0).advance(100.0)


def test_bad_counts_threads_and_executors_raise_hooke_error():
    sim = hooke.load("chain")
    for call in (lambda: sim.step(-1), lambda: sim.render(-1, 5),
                 lambda: hooke.load("chain", threads=100000),
                 lambda: hooke.load("chain", steps=-3),
                 lambda: hooke.sweep("chain", {"dt": [1e-4]}, hooke.metrics.lowest_point,
                                     executor="bogus")):
        with pytest.raises(hooke.HookeError):
            call()
    # Messages name the Python arguments, not the command line's options.
    with pytest.raises(hooke.HookeError) as e:
        sim.export(str(ROOT / "target" / "no-such-folder-xyz") + "/")
    assert "--" not in str(e.value) and 'format="ply"' in str(e.value), str(e.value)


def test_an_export_never_replaces_the_table_it_was_built_from(tmp_path):
    table = tmp_path / "my.obj"
    original = (ROOT / "assets/meshes/table.obj").read_bytes()
    table.write_bytes(original)
    sim = hooke.load("cloth-table", table=str(table), steps=8, every=4)
    with pytest.raises(hooke.HookeError, match="which this run reads"):
        sim.export(str(tmp_path / "my.pc2"))
    assert table.read_bytes() == original
    assert not (tmp_path / "my.pc2").exists()


def test_scene_keys_change_the_physics():
    soft = hooke.load("hanging-cloth", duration=1.0, set={"body.springs.structural.ks": 40.0})
    stiff = hooke.load("hanging-cloth", duration=1.0)
    soft.run()
    stiff.run()
    # A tenth of the stiffness: the cloth hangs lower (1.504 m against 1.530 m on average).
    assert hooke.metrics.mean_height(soft) < hooke.metrics.mean_height(stiff) - 0.01


def runtime_warnings(sim):
    """Runs `sim` to its end and gives the texts of the RuntimeWarnings it raised."""
    import warnings

    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        sim.run()
    return [str(w.message) for w in said if issubclass(w.category, RuntimeWarning)]


def test_a_surface_through_a_collider_is_a_runtime_warning():
    # Implicit Euler at 1/60 s lets the cloth through the round table (its contacts come
    # after a step that moves the cloth centimetres); the run says so, once, naming both.
    said = runtime_warnings(hooke.load("cloth-table", integrator="implicit", dt=1 / 60,
                                       duration=1.0))
    assert len(said) == 1, said
    assert "body 'cloth'" in said[0] and "collider[1]" in said[0] and "implicit" in said[0]


def test_layers_a_large_step_lets_through_each_other_are_a_runtime_warning():
    # Implicit Euler at 4 ms folds the pile through itself (hooke check asks for under
    # 0.47 ms): said once, at the step the independent checker first finds it, 180.
    said = runtime_warnings(hooke.load("cloth-pile", integrator="implicit", dt=0.004,
                                       duration=1.0))
    assert len(said) == 1, said
    assert said[0].startswith("step 180 ") and "through itself" in said[0], said[0]


def test_a_material_is_read_set_and_written_back(tmp_path):
    # The built-in tablecloth is cotton: 0.15 kg/m² over 1.6 m square, whatever the grid.
    cotton = hooke.load("tablecloth", steps=1)
    assert abs(cotton.masses.sum() - 0.15 * 1.6 * 1.6) < 1e-12
    # A material key set from Python overrides the preset, and is refused with its key
    # when it is not a material's.
    heavy = hooke.load("tablecloth", steps=1, set={"body.material.density": 0.3})
    assert abs(heavy.masses.sum() - 0.3 * 1.6 * 1.6) < 1e-12
    with pytest.raises(hooke.HookeError, match=r"material\.preset: expected one of cotton"):
        hooke.load("tablecloth", set={"body.material.preset": "velvet"})
    # The command's scene file holds the material, and loads to the same masses.
    text = subprocess.run([hooke_bin(), "scene", "tablecloth"], check=True,
                          capture_output=True, text=True).stdout
    assert "[body.material]" in text and 'preset = "cotton"' in text
    path = tmp_path / "tablecloth.toml"
    path.write_text(text)
    again = hooke.load(str(path), steps=1)
    assert np.array_equal(again.masses, cotton.masses)


def test_a_moving_colliders_pose_is_read_at_the_current_time(tmp_path):
    text = subprocess.run([hooke_bin(), "scene", "hanging-cloth"], check=True,
                          capture_output=True, text=True).stdout
    text += """
[[collider]]
shape = { kind = "cylinder", center = [-1.5, 1.7, 0.0], radius = 0.15, thickness = 0.4 }
response = { kind = "restitution", cr = 0.0, friction = 0.3 }
motion = { keys = [{ t = 0.0, translate = [0.0, 0.0, 0.0] }, { t = 1.0, translate = [1.0, 0.0, 0.0], rotate = [0.0, 90.0, 0.0] }] }
"""
    path = tmp_path / "puck.toml"
    path.write_text(text)
    sim = hooke.load(str(path), duration=1.0)
    assert sim.collider_pose(0) is None  # the ground does not move
    sim.advance(0.5)
    translate, rotate = sim.collider_pose(1)
    assert np.allclose(translate, [0.5, 0.0, 0.0]) and np.allclose(rotate, [0.0, 45.0, 0.0])
    with pytest.raises(hooke.HookeError, match="collider 2: the scene has 2"):
        sim.collider_pose(2)


def test_render_gives_an_rgb_picture_of_the_asked_size():
    sim = hooke.load("jello-cube")
    img = sim.render(width=160, height=120, style="both", supersample=1)
    assert img.shape == (120, 160, 3) and img.dtype == np.uint8
    assert img.std() > 10, "a picture, not a blank"
    with pytest.raises(hooke.HookeError, match="style"):
        sim.render(style="wire")
    with pytest.raises(hooke.HookeError, match="pitch"):
        sim.render(pitch=90.0)


def test_render_colours_by_a_quantity_with_its_legend_and_places_the_camera():
    sim = hooke.load("hanging-cloth")
    sim.advance(0.5)
    plain = sim.render(width=320, height=240, supersample=1)
    strain = sim.render(width=320, height=240, supersample=1, color="strain", range=(-5.0, 5.0))
    assert strain.shape == plain.shape and (strain != plain).any()
    # The legend's bar at the right edge: its top is coolwarm's red end.
    right = strain[:, 200:, :].reshape(-1, 3).astype(int)
    assert ((right[:, 0] - right[:, 2]) > 100).any(), "a red end of the bar"
    near = sim.render(width=320, height=240, supersample=1, distance=1.0, shadows=False)
    assert (near != plain).any()
    with pytest.raises(hooke.HookeError, match="color"):
        sim.render(color="heat")
    with pytest.raises(hooke.HookeError, match="range"):
        sim.render(color="speed", range=(2.0, 1.0))


def test_export_writes_what_the_command_writes(tmp_path):
    import pxr.Usd  # usd-core: cargo xtask test installs it
    sim = hooke.load("chain", steps=400, every=40)
    said = sim.export(str(tmp_path / "c.usda"))
    assert "11 frames" in said
    stage = pxr.Usd.Stage.Open(str(tmp_path / "c.usda"))
    assert stage.GetEndTimeCode() == 10
    assert sim.steps_taken == 400
    with pytest.raises(
        hooke.HookeError,
        match='a folder export needs format="ply", format="obj" or format="pc2"',
    ):
        sim.export(str(tmp_path) + "/")
    # A point cache per body: the chain's one body.
    said = hooke.load("chain", steps=400, every=40).export(str(tmp_path / "caches") + "/", "pc2")
    assert "11 samples of body chain" in said, said
    assert (tmp_path / "caches" / "chain.pc2").stat().st_size == 32 + 11 * 12 * 12


def test_stepping_releases_the_gil_and_a_second_thread_is_told_the_simulation_is_busy():
    sim = hooke.load("cloth-table")
    t = threading.Thread(target=lambda: sim.advance(0.5))
    t.start()
    # This thread runs Python while the other steps only if stepping releases the GIL; it
    # finds the simulation busy then, and is told so. With the GIL held for the whole
    # advance it could run only before or after it, and would find the simulation free.
    # Nothing here depends on how fast either thread runs.
    busy = []
    while t.is_alive() and not busy:
        try:
            sim.positions
        except hooke.HookeError as e:
            busy.append(str(e))
    t.join()
    assert busy and "another thread" in busy[0], busy
    assert sim.steps_taken == round(0.5 / sim.dt)


def test_ctrl_c_interrupts_a_long_advance_after_a_whole_step():
    # A job started in the background of a non-interactive shell inherits SIGINT ignored,
    # and Python then leaves it so: give Ctrl-C its usual meaning for this test.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        ctrl_c_interrupts_a_long_advance()
    finally:
        signal.signal(signal.SIGINT, previous)


def ctrl_c_interrupts_a_long_advance():
    sim = hooke.load("cloth-table")

    def interrupt_once_stepping():
        # The simulation refuses other threads once the advance holds it.
        while True:
            try:
                sim.steps_taken
            except hooke.HookeError:
                break
            time.sleep(0.001)
        os.kill(os.getpid(), signal.SIGINT)

    watcher = threading.Thread(target=interrupt_once_stepping)
    with pytest.raises(KeyboardInterrupt):
        watcher.start()
        sim.advance(1000.0)
    watcher.join()
    assert 0 < sim.steps_taken < 1000.0 / sim.dt
    assert sim.time == sim.steps_taken * sim.dt


lowest_point = hooke.metrics.lowest_point

GRID = {
    "body.springs.structural.ks": [150.0, 600.0],
    "table": ["builtin:table.obj", "builtin:square-table.obj"],
}


def test_a_sweep_gives_one_row_per_point_the_same_serially_and_in_processes():
    serial = hooke.sweep("cloth-table", GRID, lowest_point, executor="serial", duration=1.0)
    assert [(r["body.springs.structural.ks"], r["table"]) for r in serial] == [
        (150.0, "builtin:table.obj"), (150.0, "builtin:square-table.obj"),
        (600.0, "builtin:table.obj"), (600.0, "builtin:square-table.obj"),
    ]
    assert len({r["metric"] for r in serial}) == 4, "every point a different run"
    pooled = hooke.sweep("cloth-table", GRID, lowest_point, max_workers=2, duration=1.0)
    assert pooled == serial


def test_a_sweep_on_a_local_ray_cluster_equals_the_same_points_run_serially():
    import ray  # cargo xtask test installs it
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        on_ray = hooke.sweep("cloth-table", GRID, lowest_point, executor="ray", duration=1.0)
    finally:
        ray.shutdown()
    serial = hooke.sweep("cloth-table", GRID, lowest_point, executor="serial", duration=1.0)
    assert on_ray == serial


def test_the_ray_example_runs_and_plots(tmp_path):
    out = tmp_path / "sweep.png"
    result = subprocess.run(
        [sys.executable, str(ROOT / "examples/sweep_ray.py"), "--quick", "--out", str(out)],
        capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    assert out.stat().st_size > 10_000
    assert "round" in result.stdout and "square" in result.stdout


def test_report_writes_the_page_and_its_numbers(tmp_path):
    page, failures = hooke.report(tmp_path / "report", quick=True)
    assert failures == []
    assert Path(page) == tmp_path / "report" / "index.html"
    text = Path(page).read_text()
    assert "Every check passed" in text
    numbers = json.loads((tmp_path / "report" / "report.json").read_text())
    orders = {s["integrator"]: (s["slope"], s["expected"]) for s in numbers["convergence"]}
    assert set(orders) == {"euler", "symplectic", "midpoint", "rk4", "implicit", "vbd", "newton"}
    for name, (slope, expected) in orders.items():
        assert abs(slope - expected) <= 0.1, (name, slope, expected)


def test_a_mesh_body_loads_with_its_faces_and_its_files_vertices(tmp_path):
    examples = ROOT / "assets" / "examples"
    sim = hooke.load(str(examples / "flag-hole.toml"), steps=10)
    faces = sim.faces
    assert faces.shape[1] == 3 and faces.dtype == np.int64
    assert faces.min() >= 0 and faces.max() < len(sim.positions)
    vertices, triangles = sim.mesh("flag")
    # The OBJ's 621 vertices, in its order, each a particle.
    assert vertices.shape == (621, 3) and len(sim.positions) == 621
    assert triangles.max() < 621
    with pytest.raises(hooke.HookeError, match="no body 'cloth'"):
        sim.mesh("cloth")
    # A vertex in no face is handed back too, in its place, though it is no particle.
    (tmp_path / "quad.obj").write_text(
        "v 0 0 0\nv 0.1 0 0\nv 9 9 9\nv 0.1 0 0.1\nv 0 0 0.1\nf 1 2 4 5\n"
    )
    (tmp_path / "quad.toml").write_text(
        'name = "quad"\n[simulation]\nintegrator = "symplectic"\ndt = 0.0001\nsteps = 1\n'
        'every = 1\n[[body]]\nname = "quad"\nshape = { kind = "mesh", path = "quad.obj" }\n'
        'material = { preset = "cotton" }\n'
    )
    sim = hooke.load(str(tmp_path / "quad.toml"), steps=1)
    vertices, triangles = sim.mesh("quad")
    assert vertices.shape == (5, 3) and len(sim.positions) == 4
    assert tuple(vertices[2]) == (9.0, 9.0, 9.0)
    assert 2 not in set(triangles.ravel().tolist())
