//! Colliders that deform and pins that follow a cache (docs/physics.md §1.2 and §2.1, "A
//! deforming collider"): a mesh whose vertices a PC2 vertex cache moves, `motion = { cache,
//! fps }`, and pinned particles that each follow their own vertex of a cache, `pin_motion =
//! { cache, fps }` (`tests/caches.rs`). Closed forms for a rising and a sliding plane; cloth on a swelling
//! sphere and on a bending tube under block descent and symplectic Euler, checked for
//! crossings by the analytic shapes the caches were made from, not by the solver's own
//! detection.

use crate::meshes::{folder, obj};
use hooke_core::Vec3;
use hooke_scene::Scene;
use std::f64::consts::PI;
use std::path::Path;

const G: f64 = 9.81;

/// The springs of the built-in cloths (cloth-table's), for the scenes here.
pub(crate) const SPRINGS: &str = "[body.springs.structural]
ks = 300.0
kd = 0.02
[body.springs.shear]
ks = 150.0
kd = 0.02
[body.springs.bend]
ks = 15.0
kd = 0.005";

/// Writes the OBJ of `vertices` and `faces` (0-based corners) at `path`.
fn write_obj(path: &Path, vertices: &[Vec3], faces: &[Vec<u32>]) {
    std::fs::write(path, obj(vertices, faces)).unwrap();
}

/// Writes a PC2 of `samples` (each a position per vertex), start frame 0, sampling 1.
pub(crate) fn write_pc2(path: &Path, samples: &[Vec<Vec3>]) {
    let mut b = b"POINTCACHE2\0".to_vec();
    b.extend(1i32.to_le_bytes());
    b.extend((samples[0].len() as i32).to_le_bytes());
    b.extend(0f32.to_le_bytes());
    b.extend(1f32.to_le_bytes());
    b.extend((samples.len() as i32).to_le_bytes());
    for s in samples {
        for p in s {
            for c in [p.x, p.y, p.z] {
                b.extend((c as f32).to_le_bytes());
            }
        }
    }
    std::fs::write(path, b).unwrap();
}

/// Builds the scene `text` whose files are in `dir` ([`crate::meshes::build`]), which
/// must build.
pub(crate) fn build(text: &str, dir: &Path) -> Scene {
    crate::meshes::build(text, dir).unwrap()
}

/// A 2 m square in y = 0 (one quad) and its cache at 50 fps for 1.2 s, each sample the
/// square moved by `motion(t)`.
pub(crate) fn moving_plane(dir: &Path, motion: impl Fn(f64) -> Vec3) {
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(x, z)| Vec3::new(x, 0.0, z))
        .to_vec();
    write_obj(&dir.join("plane.obj"), &corners, &[vec![0, 3, 2, 1]]);
    let samples: Vec<Vec<Vec3>> = (0..=60)
        .map(|k| {
            let m = motion(k as f64 / 50.0);
            corners.iter().map(|c| c + m).collect()
        })
        .collect();
    write_pc2(&dir.join("plane.pc2"), &samples);
}

/// One particle at rest at `at` over the moving plane, with Coulomb `mu`, stepped by
/// `integrator` at `dt`.
fn point_on_plane(dir: &Path, at: Vec3, mu: f64, (integrator, dt): (&str, f64)) -> Scene {
    point_on_plane_from(dir, "plane.pc2", at, mu, (integrator, dt))
}

/// [`point_on_plane`] with the plane's motion read from `cache`.
fn point_on_plane_from(
    dir: &Path,
    cache: &str,
    at: Vec3,
    mu: f64,
    (integrator, dt): (&str, f64),
) -> Scene {
    build(
        &format!(
            r#"
name = "point"
[simulation]
integrator = "{integrator}"
dt = {dt}
duration = 1.0
every = 1
gravity = [0.0, -9.81, 0.0]
[[body]]
name = "point"
mass = 0.1
[body.shape]
kind = "points"
positions = [[{}, {}, {}]]
[[collider]]
shape = {{ kind = "mesh", path = "plane.obj" }}
response = {{ kind = "restitution", cr = 0.0, friction = {mu} }}
motion = {{ cache = "{cache}", fps = 50.0 }}
"#,
            at.x, at.y, at.z
        ),
        dir,
    )
}

/// A plane that rises at 0.2 m/s carries a particle resting on it: after 1 s the particle
/// is 0.2 m higher, within a millimetre, and rises at the plane's speed within 1 %, under
/// symplectic Euler and under block descent at a frame a step.
#[test]
fn a_particle_on_a_rising_mesh_plane_rises_with_it() {
    let dir = folder("deforming-rise");
    moving_plane(&dir, |t| Vec3::new(0.0, 0.2 * t, 0.0));
    for run in [("symplectic", 1e-3), ("vbd", 1.0 / 60.0)] {
        let mut scene = point_on_plane(&dir, Vec3::new(0.1, 1e-3, 0.2), 0.5, run);
        let steps = (1.0 / run.1).round() as u64;
        scene.simulation.advance(steps).unwrap();
        let p = scene.simulation.particles();
        assert!(
            (p.x[0].y - 0.2).abs() < 1e-3,
            "{run:?}: at y = {} after 1 s, the plane at 0.2",
            p.x[0].y
        );
        assert!(
            (p.v[0].y / 0.2 - 1.0).abs() < 0.01,
            "{run:?}: rising at {} m/s, the plane at 0.2",
            p.v[0].y
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// The same motion as an OBJ sequence (`plane_####.obj`, a file per sample holding the
/// PC2's 32-bit positions, numbered from 7) moves the plane as its PC2 does: the particle
/// resting on the sliding, rising plane follows the same trajectory, bit for bit, under
/// block descent.
#[test]
fn an_obj_sequence_animates_a_collider_as_its_point_cache_does() {
    let dir = folder("deforming-sequence");
    let motion = |t: f64| Vec3::new(0.3 * t, 0.1 * t, 0.0);
    moving_plane(&dir, motion);
    let corners =
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, z)| Vec3::new(x, 0.0, z));
    for k in 0..=60 {
        let m = motion(k as f64 / 50.0);
        let at: Vec<Vec3> = corners
            .iter()
            .map(|c| (c + m).map(|v| f64::from(v as f32)))
            .collect();
        let file = dir.join(format!("plane_{:04}.obj", k + 7));
        std::fs::write(file, obj(&at, &[vec![0, 3, 2, 1]])).unwrap();
    }
    let run = |cache: &str| {
        let mut scene =
            point_on_plane_from(&dir, cache, Vec3::new(0.1, 1e-3, 0.2), 0.5, ("vbd", 0.02));
        (0..40)
            .map(|_| {
                scene.simulation.advance(1).unwrap();
                scene.simulation.particles().x[0]
            })
            .collect::<Vec<_>>()
    };
    let (cached, sequence) = (run("plane.pc2"), run("plane_####.obj"));
    assert_eq!(cached, sequence);
    assert!(
        (cached[39].x - 0.1 - 0.3 * 0.8).abs() < 0.01,
        "{:?}",
        cached[39]
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A plane that slides sideways at 0.5 m/s under a particle at rest on it (μ = 0.2) drags
/// it as Coulomb says: the particle's speed grows at μ g = 1.962 m/s² until it matches
/// the plane's, at 0.255 s, and then rides it. At 0.15 s it has gone ½ μ g t² = 22.1 mm
/// (within 3 %) and at 1 s it moves at 0.5 m/s (within 0.5 %); under symplectic Euler at
/// two steps a factor of 8 apart.
#[test]
fn a_particle_on_a_sliding_mesh_plane_is_carried_as_coulomb_says() {
    let dir = folder("deforming-slide");
    let (u, mu) = (0.5, 0.2);
    moving_plane(&dir, |t| Vec3::new(u * t, 0.0, 0.0));
    for dt in [1e-3, 1.25e-4] {
        let mut scene = point_on_plane(&dir, Vec3::new(0.0, 1e-4, 0.0), mu, ("symplectic", dt));
        scene
            .simulation
            .advance((0.15 / dt).round() as u64)
            .unwrap();
        let x = scene.simulation.particles().x[0].x;
        let expected = 0.5 * mu * G * 0.15 * 0.15;
        assert!(
            (x / expected - 1.0).abs() < 0.03,
            "dt {dt}: moved {x} m in 0.15 s, Coulomb says {expected} m"
        );
        scene
            .simulation
            .advance((0.85 / dt).round() as u64)
            .unwrap();
        let v = scene.simulation.particles().v[0].x;
        assert!(
            (v / u - 1.0).abs() < 0.005,
            "dt {dt}: at {v} m/s after 1 s, the plane at {u}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A UV sphere of `rings` × `sectors` (poles fanned, quads between), unit radius.
fn unit_sphere(rings: usize, sectors: usize) -> (Vec<Vec3>, Vec<Vec<u32>>) {
    let mut v = vec![Vec3::new(0.0, 1.0, 0.0)];
    for i in 1..rings {
        let th = PI * i as f64 / rings as f64;
        for j in 0..sectors {
            let ph = 2.0 * PI * j as f64 / sectors as f64;
            v.push(Vec3::new(
                th.sin() * ph.cos(),
                th.cos(),
                th.sin() * ph.sin(),
            ));
        }
    }
    v.push(Vec3::new(0.0, -1.0, 0.0));
    let at = |i: usize, j: usize| (1 + (i - 1) * sectors + j % sectors) as u32;
    let mut f = Vec::new();
    for j in 0..sectors {
        f.push(vec![0, at(1, j + 1), at(1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..sectors {
            f.push(vec![at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    let last = v.len() as u32 - 1;
    for j in 0..sectors {
        f.push(vec![last, at(rings - 1, j), at(rings - 1, j + 1)]);
    }
    (v, f)
}

/// A cloth of `n × n` over a ball at (0, 0.5, 0) whose radius swells from 0.3 m to 0.4 m
/// and back each second (24 fps cache), stepped by `integrator` at `dt`.
fn cloth_on_swelling_ball(dir: &Path, n: usize, (integrator, dt): (&str, f64)) -> Scene {
    let (v, f) = unit_sphere(12, 24);
    write_obj(&dir.join("ball.obj"), &v, &f);
    let samples: Vec<Vec<Vec3>> = (0..=48)
        .map(|k| {
            let r = swelling_radius(k as f64 / 24.0);
            v.iter().map(|p| Vec3::new(0.0, 0.5, 0.0) + p * r).collect()
        })
        .collect();
    write_pc2(&dir.join("swell.pc2"), &samples);
    let spacing = 1.2 / (n - 1) as f64;
    build(
        &format!(
            r#"
name = "swell"
[simulation]
integrator = "{integrator}"
dt = {dt}
duration = 2.0
every = 1
gravity = [0.0, -9.81, 0.0]
drag = 0.002
[[body]]
name = "cloth"
mass = {}
origin = [-0.6, 0.95, -0.6]
thickness = 0.005
friction = 0.3
[body.shape]
kind = "grid"
size = [{n}, {n}]
spacing = {spacing}
{SPRINGS}
[[collider]]
shape = {{ kind = "ground", height = 0.0 }}
response = {{ kind = "restitution", cr = 0.2, friction = 0.5 }}
[[collider]]
shape = {{ kind = "mesh", path = "ball.obj" }}
response = {{ kind = "restitution", cr = 0.0, friction = 0.5 }}
motion = {{ cache = "swell.pc2", fps = 24.0 }}
"#,
            0.4 / (n * n) as f64
        ),
        dir,
    )
}

/// The ball's radius at `t`: 0.3 m swelling to 0.4 m and back each second.
fn swelling_radius(t: f64) -> f64 {
    0.3 + 0.1 * (PI * t).sin().powi(2)
}

/// The deepest any particle or cloth edge (sampled at its ends and three points between)
/// is inside the faceted ball at time `t`, metres: the faces of a 12 × 24 UV sphere lie at
/// least `cos(π/12)·cos(π/24)` of the radius from its centre (less between samples, where a
/// vertex moves on a straight line: within a part in 10⁴ here), so a point nearer than that
/// is inside whatever the triangulation.
fn ball_depth(scene: &Scene, t: f64) -> f64 {
    let centre = Vec3::new(0.0, 0.5, 0.0);
    let inner = swelling_radius(t) * (PI / 12.0).cos() * (PI / 24.0).cos() * (1.0 - 1e-3);
    let x = &scene.simulation.particles().x;
    let mut deepest = 0.0_f64;
    for tri in &scene.bodies[0].triangles {
        for k in 0..3 {
            let (a, b) = (x[tri[k] as usize], x[tri[(k + 1) % 3] as usize]);
            for s in [0.0, 0.25, 0.5, 0.75] {
                let p = a + (b - a) * s;
                deepest = deepest.max(inner - (p - centre).norm());
            }
        }
    }
    deepest
}

/// A cloth on a ball that swells by a third and shrinks back twice in 2 s, under block
/// descent at a frame a step (24 × 24) and symplectic Euler at 2e-4 s (12 × 12): no particle
/// and no cloth edge is ever inside the ball, checked at every step against the ball the
/// cache was made from; and the cloth rides it, its top within 2 cm of the ball's top
/// plus the thickness when the ball is largest (t = 1.5 s).
#[test]
fn a_cloth_on_a_swelling_ball_never_enters_it() {
    let dir = folder("deforming-swell");
    for (n, run) in [(24, ("vbd", 1.0 / 60.0)), (12, ("symplectic", 2e-4))] {
        let mut scene = cloth_on_swelling_ball(&dir, n, run);
        let steps = (2.0 / run.1).round() as u64;
        for step in 1..=steps {
            scene.simulation.advance(1).unwrap();
            let t = scene.simulation.time();
            let depth = ball_depth(&scene, t);
            assert!(
                depth <= 0.0,
                "{run:?}: {depth} m inside the ball at t = {t} s (step {step})"
            );
            if step == (1.5 / run.1).round() as u64 {
                let top = scene
                    .simulation
                    .particles()
                    .x
                    .iter()
                    .map(|p| p.y)
                    .fold(0.0, f64::max);
                let ball = 0.5 + swelling_radius(1.5);
                assert!(
                    (top - ball).abs() < 0.02,
                    "{run:?}: the cloth's top at {top} m, the ball's at {ball} m"
                );
            }
        }
        let notices = scene.simulation.notice_tally();
        assert!(notices.is_empty(), "{run:?}: {notices:?}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A capped tube of radius 0.1 m along x from −0.6 m to 0.6 m at height 0.5 m, 16 sides,
/// rings every 5 cm; its cache (24 fps, 2 s) bends the half beyond x = 0 down about the z
/// axis through (0, 0.5, 0) by up to 40° and back, as an elbow bends.
fn bending_tube(dir: &Path) {
    let (sides, rings) = (16, 25);
    let mut v = Vec::new();
    for i in 0..rings {
        let x = -0.6 + 0.05 * i as f64;
        for j in 0..sides {
            let a = 2.0 * PI * j as f64 / sides as f64;
            v.push(Vec3::new(x, 0.5 + 0.1 * a.cos(), 0.1 * a.sin()));
        }
    }
    v.push(Vec3::new(-0.6, 0.5, 0.0));
    v.push(Vec3::new(0.6, 0.5, 0.0));
    let at = |i: usize, j: usize| (i * sides + j % sides) as u32;
    let mut f = Vec::new();
    for i in 0..rings - 1 {
        for j in 0..sides {
            f.push(vec![at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    let (left, right) = (v.len() as u32 - 2, v.len() as u32 - 1);
    for j in 0..sides {
        f.push(vec![left, at(0, j + 1), at(0, j)]);
        f.push(vec![right, at(rings - 1, j), at(rings - 1, j + 1)]);
    }
    write_obj(&dir.join("tube.obj"), &v, &f);
    let elbow = Vec3::new(0.0, 0.5, 0.0);
    let samples: Vec<Vec<Vec3>> = (0..=48)
        .map(|k| {
            let angle = -(40.0_f64).to_radians() * (PI * k as f64 / 48.0).sin().powi(2);
            let turn = nalgebra::Rotation3::from_axis_angle(&Vec3::z_axis(), angle);
            v.iter()
                .map(|p| {
                    if p.x > 1e-9 {
                        elbow + turn * (p - elbow)
                    } else {
                        *p
                    }
                })
                .collect()
        })
        .collect();
    write_pc2(&dir.join("tube.pc2"), &samples);
}

/// A 20 × 6 sheet dropped along a tube that bends at its middle by 40° and straightens in
/// 2 s, under block descent at a frame a step and symplectic Euler at 2e-4 s: no exported
/// frame has a cloth–tube or cloth–cloth crossing (the suite's own crossing count on the
/// exported meshes, the tube where its cache has it), and the sheet's far end follows the
/// arm down: at 1 s it is below the elbow's height by at least 0.15 m.
#[test]
fn a_sheet_on_a_bending_tube_never_crosses_it() {
    let dir = folder("deforming-tube");
    bending_tube(&dir);
    for (run, every) in [(("vbd", 1.0 / 60.0), 1), (("symplectic", 2e-4), 84)] {
        let scene = |duration: f64| {
            build(
                &format!(
                    r#"
name = "tube"
[simulation]
integrator = "{}"
dt = {}
duration = {duration}
every = {every}
gravity = [0.0, -9.81, 0.0]
drag = 0.002
[[body]]
name = "sheet"
mass = 0.0015
origin = [-0.5, 0.63, -0.15]
thickness = 0.005
friction = 0.5
[body.shape]
kind = "grid"
size = [20, 6]
spacing = 0.05
{SPRINGS}
[[collider]]
shape = {{ kind = "ground", height = 0.0 }}
response = {{ kind = "restitution", cr = 0.2, friction = 0.5 }}
[[collider]]
shape = {{ kind = "mesh", path = "tube.obj" }}
response = {{ kind = "restitution", cr = 0.0, friction = 0.5 }}
motion = {{ cache = "tube.pc2", fps = 24.0 }}
"#,
                    run.0, run.1
                ),
                &dir,
            )
        };
        let mut half = scene(1.0);
        half.simulation.advance(half.steps).unwrap();
        let x = &half.simulation.particles().x;
        // The grid numbers particle (i along x, k along z) as i·6 + k: the far edge is i = 19.
        let far = x[19 * 6..]
            .iter()
            .map(|p| p.y)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(far < 0.5 - 0.15, "{run:?}: the far end at {far} m at 1 s");
        crate::contact::assert_scene_never_crosses(scene(2.0), &format!("tube-{}", run.0));
    }
    std::fs::remove_dir_all(dir).unwrap();
}
