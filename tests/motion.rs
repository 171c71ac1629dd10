//! Keyframed pins (`[body.pin_motion]`, docs/physics.md §1.2): the pinned particles sit at
//! their keyed positions at every step, whatever the integrator, and carry the cloth.

use crate::common::{builtin, root};
use crate::large_steps::sheet_with;
use hooke_core::{Integrator, Vec3};
use hooke_scene::spec::{Finite, KeySpec, MotionSpec};
use hooke_scene::{Overrides, Scene};

/// A key in the scene format.
fn key(t: f64, translate: [f64; 3], rotate: Option<[f64; 3]>) -> KeySpec {
    KeySpec {
        t: Finite::of(t),
        translate: translate.map(Finite::of),
        rotate: rotate.map(|r| r.map(Finite::of)),
    }
}

/// The keys of the test: still for 0.1 s, carried 0.5 m along x by 0.6 s, then lifted 0.2 m
/// while turned 60° about y by 1.0 s, then held.
fn keys() -> Vec<KeySpec> {
    vec![
        key(0.1, [0.0; 3], None),
        key(0.6, [0.5, 0.0, 0.0], None),
        key(1.0, [0.5, 0.2, 0.0], Some([0.0, 60.0, 0.0])),
    ]
}

/// Where the test's keys put a pinned particle that started at `x`, its pins' centroid at
/// the start being `c`, at time `t`: worked out here from the contract, not by the library.
fn expected(x: Vec3, c: Vec3, t: f64) -> Vec3 {
    let (tr, deg) = if t <= 0.1 {
        (Vec3::zeros(), 0.0)
    } else if t <= 0.6 {
        (Vec3::new(0.5 * (t - 0.1) / 0.5, 0.0, 0.0), 0.0)
    } else if t <= 1.0 {
        let s = (t - 0.6) / 0.4;
        (Vec3::new(0.5, 0.2 * s, 0.0), 60.0 * s)
    } else {
        (Vec3::new(0.5, 0.2, 0.0), 60.0)
    };
    let (sin, cos) = deg.to_radians().sin_cos();
    let o = x - c;
    // About y: x' = cos x + sin z, z' = -sin x + cos z.
    let turned = Vec3::new(cos * o.x + sin * o.z, o.y, -sin * o.x + cos * o.z);
    c + tr + turned
}

/// `hanging-cloth` (two corners pinned) with the test's keys, under `integrator` at `dt`.
fn carried(integrator: Integrator, dt: f64) -> Scene {
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    spec.bodies[0].pin_motion = Some(MotionSpec::of_keys(keys()));
    let overrides = Overrides {
        integrator: Some(integrator),
        dt: Some(dt),
        ..Overrides::default()
    };
    overrides.apply(&mut spec).unwrap();
    spec.build(&root().join("assets/scenes")).unwrap()
}

/// With symplectic Euler at the scene's step, the implicit integrator at 1 ms and block
/// descent at 1/60 s, every pinned particle is at its keyed position within 1e-9 m after
/// every step of 1.2 s, and the cloth is carried: after 6 s its centroid is 0.5 m along x
/// and 0.2 m up from where the same run without keys has it (within 5 cm), as the corners
/// are (the turn is about the vertical through the corners' centroid, under which the
/// cloth hangs).
#[test]
fn keyframed_pins_sit_at_their_keys_at_every_step_and_carry_the_cloth() {
    for (integrator, dt) in [
        (Integrator::Symplectic, 2.5e-4),
        (Integrator::Implicit, 1e-3),
        (Integrator::Vbd, 1.0 / 60.0),
    ] {
        let still = {
            let overrides = Overrides {
                integrator: Some(integrator),
                dt: Some(dt),
                ..Overrides::default()
            };
            let mut scene = builtin("hanging-cloth", &overrides);
            scene.simulation.advance((6.0 / dt).round() as u64).unwrap();
            centroid(&scene)
        };
        let mut scene = carried(integrator, dt);
        let pins: Vec<usize> = scene.spec.bodies[0].pins.indices().to_vec();
        let start: Vec<Vec3> = pins
            .iter()
            .map(|&i| scene.simulation.particles().x[i])
            .collect();
        let c = start.iter().sum::<Vec3>() / start.len() as f64;
        let steps = (1.2 / dt).round() as u64;
        for _ in 0..steps {
            scene.simulation.step().unwrap();
            let t = scene.simulation.time();
            for (&i, &x0) in pins.iter().zip(&start) {
                let at = scene.simulation.particles().x[i];
                let want = expected(x0, c, t);
                assert!(
                    (at - want).norm() < 1e-9,
                    "{integrator:?} t {t}: pin {i} at {at:?}, keyed {want:?}"
                );
            }
        }
        // Let it swing out for the rest of the 6 s it hung still for.
        let rest = (4.8 / dt).round() as u64;
        scene.simulation.advance(rest).unwrap();
        let moved = centroid(&scene) - still;
        assert!(
            (moved.x - 0.5).abs() < 0.05 && (moved.y - 0.2).abs() < 0.05,
            "{integrator:?}: the cloth moved by {moved:?}"
        );
    }
}

/// Issue 54: `hanging-cloth` whose pins are lifted 30 m in one second (from rest to 30 m/s
/// at t = 0.5 s) under block descent at 1/60 s. The pins' work is counted, so the energy
/// watch lets it run; the cloth, dragged through the steps' parts, follows its pins and
/// ends hanging below them (symplectic Euler at 2.5e-4 s: lowest point 30.984 m), its
/// energy no more than it started with plus the work the pins did.
#[test]
fn a_cloth_lifted_30_m_by_its_pins_follows_them_under_block_descent() {
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    spec.bodies[0].pin_motion = Some(MotionSpec::of_keys(vec![
        key(0.5, [0.0, 0.0, 0.0], None),
        key(1.5, [0.0, 30.0, 0.0], None),
    ]));
    spec.simulation.duration = Some(hooke_scene::spec::Positive::of(4.0));
    let overrides = Overrides {
        integrator: Some(Integrator::Vbd),
        dt: Some(1.0 / 60.0),
        ..Overrides::default()
    };
    overrides.apply(&mut spec).unwrap();
    let mut scene = spec.build(&root().join("assets/scenes")).unwrap();
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    let x = &scene.simulation.particles().x;
    let lowest = x.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    let highest = x.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
    assert!(
        (30.9..31.1).contains(&lowest) && (highest - 32.0).abs() < 1e-9,
        "the cloth hangs from {lowest} m to {highest} m"
    );
}

fn centroid(scene: &Scene) -> Vec3 {
    let x = &scene.simulation.particles().x;
    x.iter().sum::<Vec3>() / x.len() as f64
}

/// Keys without pins, and keys out of order, are refused with their keys.
#[test]
fn pin_motions_without_pins_or_in_the_wrong_order_are_refused() {
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    spec.bodies[0].pin_motion = Some(MotionSpec::of_keys(keys()));
    spec.bodies[0].pins = Default::default();
    let e = spec
        .build(&root().join("assets/scenes"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("pin_motion") && e.contains("`pins`"), "{e}");
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    let mut keys = keys();
    keys.swap(0, 2);
    spec.bodies[0].pin_motion = Some(MotionSpec::of_keys(keys));
    let e = spec
        .build(&root().join("assets/scenes"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("pin_motion.keys") && e.contains("times must increase"),
        "{e}"
    );
}

/// A sheet of 10 × 10 particles, 0.4 m wide, thickness 5 mm, lying a thickness above a
/// round platform (a cylinder collider, top at y = 0.5, radius 1.5 m) with Coulomb `mu`,
/// which stands still for 0.1 s and then moves along x at 1 m/s; stepped by `integrator`
/// at `dt`.
fn on_a_moving_platform(mu: f64, run: (&str, f64)) -> Scene {
    let platform = format!(
        r#"
[[collider]]
shape = {{ kind = "cylinder", center = [0.0, 0.5, 0.0], radius = 1.5, thickness = 0.1 }}
response = {{ kind = "restitution", cr = 0.0, friction = {mu} }}
motion = {{ keys = [{{ t = 0.1, translate = [0.0, 0.0, 0.0] }}, {{ t = 2.1, translate = [2.0, 0.0, 0.0] }}] }}
"#
    );
    sheet_with(10, [-0.2, 0.505, -0.2], 0.0, &platform, run)
}

/// The sheet's centroid along x.
fn along_x(scene: &Scene) -> f64 {
    centroid(scene).x
}

/// A platform that starts moving at 1 m/s under a sheet drags it by Coulomb friction: the
/// sheet accelerates at `μ g` (2.94 m/s² for μ = 0.3) until it matches the platform's speed
/// (at 0.1 + 1/(μ g) = 0.44 s), then rides along at 1 m/s; with symplectic Euler at 2.5e-4 s,
/// the implicit integrator at 1e-3 s and block descent at 1/60 s. The acceleration is the second difference of the
/// centroid at 0.15, 0.25 and 0.35 s, within 3 %; the speed at 0.8 to 1.0 s within 1 %.
#[test]
fn a_moving_platform_drags_a_sheet_at_mu_g_until_it_matches_its_speed() {
    let mu = 0.3;
    for (integrator, dt) in [
        ("symplectic", 2.5e-4),
        ("implicit", 1e-3),
        ("vbd", 1.0 / 60.0),
    ] {
        let mut scene = on_a_moving_platform(mu, (integrator, dt));
        let at = |scene: &mut Scene, t: f64| {
            let steps = (t / dt).round() as u64 - scene.simulation.steps();
            scene.simulation.advance(steps).unwrap();
            along_x(scene)
        };
        let (a, b, c) = (
            at(&mut scene, 0.15),
            at(&mut scene, 0.25),
            at(&mut scene, 0.35),
        );
        let accel = (c - 2.0 * b + a) / (0.1 * 0.1);
        let expected = mu * 9.81;
        assert!(
            (accel / expected - 1.0).abs() < 0.03,
            "{integrator}: acceleration {accel} m/s², expected μ g = {expected}"
        );
        let (d, e) = (at(&mut scene, 0.8), at(&mut scene, 1.0));
        let speed = (e - d) / 0.2;
        assert!(
            (speed - 1.0).abs() < 0.01,
            "{integrator}: rides at {speed} m/s"
        );
    }
}

/// `cloth-table` on the analytic cylinder table (top at y = 1, radius 0.6 m, stick), the
/// table keyed to slide 0.3 m along x from 1.5 s to 2.5 s, after the cloth has landed; with
/// the scene's symplectic Euler, or under `run` (integrator and step, a frame per step).
fn sliding_table(run: Option<(Integrator, f64)>) -> Scene {
    let mut spec = hooke_scene::builtin::builtin("cloth-table").unwrap();
    let overrides = Overrides {
        table: Some("cylinder".parse().unwrap()),
        integrator: run.map(|r| r.0),
        dt: run.map(|r| r.1),
        every: run.map(|_| 1),
        ..Overrides::default()
    };
    overrides.apply(&mut spec).unwrap();
    spec.colliders[1].motion = Some(MotionSpec::of_keys(vec![
        key(1.5, [0.0; 3], None),
        key(2.5, [0.3, 0.0, 0.0], None),
    ]));
    spec.build(&root().join("assets/scenes")).unwrap()
}

/// A table that slides 0.3 m under a cloth stuck to its top carries the cloth with it: the
/// particles on the top at 1.5 s have moved 0.3 m ± 3 cm along x by 3 s (stick carries a
/// touching particle at the table's velocity), no exported frame has a crossing, and the
/// exported table has moved 0.3 m; with symplectic Euler at the scene's step and with
/// block descent at 1/60 s.
#[test]
fn a_sliding_table_carries_the_cloth_stuck_to_its_top() {
    sliding_table_carries(None, "sliding-table");
    sliding_table_carries(Some((Integrator::Vbd, 1.0 / 60.0)), "sliding-table-vbd");
}

fn sliding_table_carries(run: Option<(Integrator, f64)>, tag: &str) {
    let mut scene = sliding_table(run);
    let dt = scene.simulation.dt();
    scene.simulation.advance((1.5 / dt).round() as u64).unwrap();
    let x = scene.simulation.particles().x.clone();
    let on_top: Vec<usize> = (0..x.len())
        .filter(|&i| x[i].y > 1.0 && x[i].y < 1.02 && (x[i].x.hypot(x[i].z)) < 0.55)
        .collect();
    assert!(on_top.len() > 100, "{} particles on the top", on_top.len());
    let mean_x = |x: &[Vec3]| on_top.iter().map(|&i| x[i].x).sum::<f64>() / on_top.len() as f64;
    let before = mean_x(&x);
    let rest = scene.steps - scene.simulation.steps();
    scene.simulation.advance(rest).unwrap();
    let moved = mean_x(&scene.simulation.particles().x) - before;
    assert!(
        (moved - 0.3).abs() < 0.03,
        "{tag}: the top's cloth moved {moved} m"
    );

    let last = crate::contact::assert_scene_never_crosses(sliding_table(run), tag);
    let still = sliding_table(run);
    let centre = |tris: &[[Vec3; 3]]| {
        tris.iter().flatten().map(|p| p.x).sum::<f64>() / (3 * tris.len()) as f64
    };
    let placed = hooke::export::collider_triangles(&still);
    let table_then = centre(&placed[1].1);
    // The frame's colliders: the ground's two triangles first, then the table's.
    let table_now = centre(&last.colliders[2..]);
    assert!(
        ((table_now - table_then) - 0.3).abs() < 1e-9,
        "{tag}: the exported table moved {} m",
        table_now - table_then
    );
}

/// `hanging-cloth` run for 5 s with `collider` (TOML) added, under `run` (integrator and
/// step; `None` keeps the scene's symplectic Euler at 2.5e-4 s, a frame per 40 steps; block
/// descent exports every step).
fn swept(collider: &str, run: Option<(Integrator, f64)>) -> Scene {
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    spec.simulation.duration = Some(hooke_scene::spec::Positive::of(5.0));
    if let Some((integrator, dt)) = run {
        let overrides = Overrides {
            integrator: Some(integrator),
            dt: Some(dt),
            every: Some(1),
            ..Overrides::default()
        };
        overrides.apply(&mut spec).unwrap();
    }
    spec.colliders.push(toml::from_str(collider).unwrap());
    spec.build(&root().join("assets/scenes")).unwrap()
}

/// Where a still `hanging-cloth` is after 5 s: its centroid.
fn still_hanging() -> Vec3 {
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    spec.simulation.duration = Some(hooke_scene::spec::Positive::of(5.0));
    let mut scene = spec.build(&root().join("assets/scenes")).unwrap();
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    centroid(&scene)
}

/// Runs `swept(collider, run)` to its end and asserts that the cloth was pushed (its
/// centroid moved more than 5 cm from where the still cloth hangs), then runs it again
/// exporting every frame and asserts that none has a cloth–collider or cloth–cloth
/// crossing. Returns the last exported frame.
fn sweep_leaves_no_crossing(
    collider: &str,
    run: Option<(Integrator, f64)>,
    tag: &str,
) -> crate::contact::Frame {
    let mut scene = swept(collider, run);
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    let pushed = (centroid(&scene) - still_hanging()).norm();
    assert!(pushed > 0.05, "{tag}: the cloth moved {pushed} m");
    crate::contact::assert_scene_never_crosses(swept(collider, run), tag)
}

/// A puck (a cylinder 0.3 m across and 0.4 m tall) keyed through `hanging-cloth` at
/// 0.7 m/s, from 1 m in front of it to 0.4 m behind it, between 2 s and 4 s: no exported
/// frame of the 5 s run has a crossing, with symplectic Euler at the scene's step.
#[test]
fn a_puck_swept_through_a_hanging_cloth_leaves_no_crossing() {
    let puck = r#"
shape = { kind = "cylinder", center = [-1.5, 1.7, 0.0], radius = 0.15, thickness = 0.4 }
response = { kind = "restitution", cr = 0.0, friction = 0.3 }
motion = { keys = [{ t = 2.0, translate = [0.0, 0.0, 0.0] }, { t = 4.0, translate = [1.4, 0.0, 0.0] }] }
"#;
    sweep_leaves_no_crossing(puck, None, "swept-puck");
}

/// A ball 0.4 m across (the analytic `sphere`) keyed through `hanging-cloth` at 0.8 m/s,
/// from 0.8 m in front of it to 0.3 m behind it, between 2 s and 4 s: no exported frame has
/// a crossing, with the scene's symplectic Euler and with block descent at 1/60 s (whose
/// step is split where the ball would close more than half of a gap, docs/physics.md
/// §4.1); and the exported ball has moved the keyed 1.6 m.
#[test]
fn a_ball_swept_through_a_hanging_cloth_leaves_no_crossing_with_either_integrator() {
    let ball = r#"
shape = { kind = "sphere", center = [-1.3, 1.55, 0.0], radius = 0.2 }
response = { kind = "restitution", cr = 0.0, friction = 0.3 }
motion = { keys = [{ t = 2.0, translate = [0.0, 0.0, 0.0] }, { t = 4.0, translate = [1.6, 0.0, 0.0] }] }
"#;
    for (run, tag) in [
        (None, "swept-ball"),
        (Some((Integrator::Vbd, 1.0 / 60.0)), "swept-ball-vbd"),
    ] {
        let last = sweep_leaves_no_crossing(ball, run, tag);
        // The frame's colliders: the ground's two triangles first, then the ball's.
        let ball_x = last.colliders[2..]
            .iter()
            .flatten()
            .map(|p| p.x)
            .sum::<f64>()
            / (3 * (last.colliders.len() - 2)) as f64;
        assert!(
            (ball_x - (-1.3 + 1.6)).abs() < 1e-3,
            "{tag}: the exported ball ends at x = {ball_x}"
        );
    }
}

/// Issue 54: the same ball thrown through the cloth at 30 m/s and at 1000 m/s (1.6 m in
/// 53 ms and in 1.6 ms) under block descent at 1/60 s. Each step it passes is taken in as
/// many parts as keep the ball from closing more than half of any gap (about 200 parts in
/// the step it passes at either speed): no exported frame has a crossing, no cloth vertex
/// is ever inside the ball, and the run has nothing to warn of.
#[test]
fn a_thrown_ball_passes_a_hanging_cloth_without_a_crossing_under_block_descent() {
    for (span, tag) in [(0.0533, "ball-30"), (0.0016, "ball-1000")] {
        let ball = format!(
            r#"
shape = {{ kind = "sphere", center = [-1.3, 1.55, 0.0], radius = 0.2 }}
response = {{ kind = "restitution", cr = 0.0, friction = 0.3 }}
motion = {{ keys = [{{ t = 2.0, translate = [0.0, 0.0, 0.0] }}, {{ t = {}, translate = [1.6, 0.0, 0.0] }}] }}
"#,
            2.0 + span
        );
        let thrown = || {
            let mut scene = swept(&ball, Some((Integrator::Vbd, 1.0 / 60.0)));
            scene.steps = 160; // 2.67 s: the ball has passed and stopped
            scene
        };
        let mut scene = thrown();
        let centre = |t: f64| Vec3::new(-1.3 + 1.6 * ((t - 2.0) / span).clamp(0.0, 1.0), 1.55, 0.0);
        for _ in 0..scene.steps {
            scene.simulation.step().unwrap();
            let c = centre(scene.simulation.time());
            let nearest = scene
                .simulation
                .particles()
                .x
                .iter()
                .map(|x| (x - c).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest >= 0.2,
                "{tag}: a vertex {nearest} m from the centre at t = {}",
                scene.simulation.time()
            );
        }
        let notices = scene.simulation.notice_tally();
        assert!(notices.is_empty(), "{tag}: {notices:?}");
        crate::contact::assert_scene_never_crosses(thrown(), tag);
    }
}

/// A paddle (the shipped ball stretched to 0.8 × 0.16 × 0.16 m) turning once about y while
/// it moves 0.3 m towards `hanging-cloth`, its tips sweeping through the cloth at up to
/// 1.3 m/s: no exported frame has a crossing under block descent at 1/60 s, whose parts
/// bound the turn as well as the translation (docs/physics.md §4.1).
#[test]
fn a_spinning_paddle_through_a_hanging_cloth_leaves_no_crossing_under_block_descent() {
    let paddle = r#"
shape = { kind = "mesh", path = "builtin:ball.obj", translate = [-1.0, 1.3, 0.0], scale = [0.4, 0.08, 0.08] }
response = { kind = "restitution", cr = 0.0, friction = 0.5 }
motion = { keys = [{ t = 1.5, translate = [0.0, 0.0, 0.0] }, { t = 3.5, translate = [0.3, 0.0, 0.0], rotate = [0.0, 360.0, 0.0] }] }
"#;
    sweep_leaves_no_crossing(paddle, Some((Integrator::Vbd, 1.0 / 60.0)), "paddle-vbd");
}

/// A platform that lifts a sheet 20 m in 2 s (10 m/s) gives it far more energy than the
/// energy watch allows a still scene (`10 M |g| (L + 1 m)`, about 150 J/kg here, against
/// the 200 J/kg of the lift alone); the watch bounds a moving collider's work by its keys
/// (docs/physics.md §7), so the run is not stopped, and the sheet, thrown up when the
/// platform stops, ends back on the raised top.
#[test]
fn the_energy_watch_allows_the_work_of_a_moving_collider() {
    let platform = r#"
[[collider]]
shape = { kind = "cylinder", center = [0.0, 0.5, 0.0], radius = 1.5, thickness = 0.1 }
response = { kind = "restitution", cr = 0.0, friction = 0.3 }
motion = { keys = [{ t = 0.1, translate = [0.0, 0.0, 0.0] }, { t = 2.1, translate = [0.0, 20.0, 0.0] }] }
"#;
    for run in [("symplectic", 2.5e-4), ("vbd", 1.0 / 60.0)] {
        let mut scene = sheet_with(10, [-0.2, 0.505, -0.2], 0.0, platform, run);
        // Thrown up at 10 m/s when the platform stops, it lands again 2.04 s later.
        let steps = (5.0 / run.1).round() as u64;
        scene
            .simulation
            .advance(steps)
            .unwrap_or_else(|e| panic!("{}: {e}", run.0));
        let y = centroid(&scene).y;
        assert!(
            (y - 20.505).abs() < 0.01,
            "{}: the sheet ends at y = {y}",
            run.0
        );
    }
}
