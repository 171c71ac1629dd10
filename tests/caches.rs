//! Pins that follow a cache, and caches that do not fit (docs/physics.md §1.2, docs/scenes.md
//! "Caches"): each pin at its own target at every step, and every misfit refused naming the
//! key, the file and what was expected.

use crate::deforming::{SPRINGS, build, moving_plane, write_pc2};
use crate::meshes::folder;
use hooke_core::Vec3;
use std::f64::consts::PI;

/// A cloth held by one edge whose pins follow a cache (each pin its own path: a wave
/// running along the edge, in the body's own coordinates as the grid's particles are) is
/// at its targets at every step (within 1e-12 m) and on the straight line between two samples
/// of them.
#[test]
fn pins_that_follow_a_cache_are_at_their_targets_at_every_step() {
    let dir = folder("cache-pins");
    let n = 10;
    let spacing = 0.05;
    let origin = Vec3::new(-0.25, 1.0, 0.0);
    // The grid numbers particle (i along x, k along z) as i·n + k: the edge k = 0 is
    // pinned, at (i·spacing, 0, 0) in the body's frame. Its pins rise and fall in a wave.
    let target = |sample: usize, i: usize| {
        let t = sample as f64 / 30.0;
        let lift = 0.2 * (2.0 * PI * (t - 0.1 * i as f64)).sin().max(0.0);
        Vec3::new(spacing * i as f64, lift, 0.0)
    };
    let samples: Vec<Vec<Vec3>> = (0..=30)
        .map(|k| {
            (0..n * n)
                .map(|p| {
                    if p % n == 0 {
                        target(k, p / n)
                    } else {
                        Vec3::zeros()
                    }
                })
                .collect()
        })
        .collect();
    write_pc2(&dir.join("edge.pc2"), &samples);
    let mut scene = build(
        &format!(
            r#"
name = "pins"
[simulation]
integrator = "symplectic"
dt = 1e-3
duration = 1.0
every = 10
gravity = [0.0, -9.81, 0.0]
drag = 0.002
[[body]]
name = "cloth"
mass = 0.004
origin = [{}, {}, {}]
pins = [{}]
pin_motion = {{ cache = "edge.pc2", fps = 30.0 }}
[body.shape]
kind = "grid"
size = [{n}, {n}]
spacing = {spacing}
{SPRINGS}
"#,
            origin.x,
            origin.y,
            origin.z,
            (0..n)
                .map(|i| (i * n).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        &dir,
    );
    let motion = scene.simulation.model().pin_motions[0].clone();
    let mut lowest_lifted = f64::INFINITY;
    for step in 1..=1000 {
        scene.simulation.advance(1).unwrap();
        let t = scene.simulation.time();
        let x = &scene.simulation.particles().x;
        for (i, at) in motion.positions(t) {
            assert!(
                (x[i] - at).norm() < 1e-12,
                "step {step}: pin {i} at {:?}, its target {at:?}",
                x[i]
            );
        }
        let s = t * 30.0;
        let (k, w) = (s.floor() as usize, s - s.floor());
        for i in 0..n {
            let line = origin + target(k, i) + (target((k + 1).min(30), i) - target(k, i)) * w;
            assert!(
                (x[i * n] - line).norm() < 1e-6,
                "step {step}: pin {i} at {:?}, off its path {line:?}",
                x[i * n]
            );
        }
        lowest_lifted = lowest_lifted.min(x[0].y);
    }
    assert!(
        lowest_lifted >= 1.0 - 1e-6,
        "the first pin went below its path: {lowest_lifted}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A cache that does not fit is refused, naming the key, the file and what was expected:
/// a point count other than the mesh's or the body's, keys beside a cache, a cache without
/// its frame rate, a cache on a shape that cannot deform, a cache that tears the mesh, a
/// penalty on an open mesh that deforms,
/// pins that follow a cache on a body with no pins, and a cache that is not a file.
#[test]
fn caches_that_do_not_fit_are_refused_by_name() {
    let dir = folder("cache-bad");
    moving_plane(&dir, |t| Vec3::new(0.0, 0.2 * t, 0.0));
    // Five points where the plane has four.
    write_pc2(&dir.join("five.pc2"), &[vec![Vec3::zeros(); 5]]);
    // The plane's quad written with a fifth vertex at a corner's place, torn in sample 1.
    std::fs::write(
        dir.join("torn.obj"),
        "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv 1 0 1\nf 1 4 3\nf 1 5 2\n",
    )
    .unwrap();
    let corners = [
        (-1.0, -1.0),
        (1.0, -1.0),
        (1.0, 1.0),
        (-1.0, 1.0),
        (1.0, 1.0),
    ]
    .map(|(x, z)| Vec3::new(x, 0.0, z))
    .to_vec();
    let mut torn = corners.clone();
    torn[4].y = 0.1;
    write_pc2(&dir.join("torn.pc2"), &[corners, torn]);
    let scene = |collider: &str, body: &str| {
        format!(
            r#"
name = "bad"
[simulation]
integrator = "symplectic"
dt = 1e-3
duration = 0.1
every = 1
[[body]]
name = "point"
mass = 0.1
{body}
[body.shape]
kind = "points"
positions = [[0.0, 0.5, 0.0], [0.1, 0.5, 0.0]]
[[collider]]
{collider}
response = {{ kind = "restitution", cr = 0.0, friction = 0.5 }}
"#
        )
    };
    let plane = r#"shape = { kind = "mesh", path = "plane.obj" }"#;
    let cases = [
        (
            format!("{plane}\nmotion = {{ cache = \"five.pc2\", fps = 24.0 }}"),
            "",
            vec![
                "collider[0].motion.cache",
                "five.pc2",
                "5 points",
                "4 vertices",
            ],
        ),
        (
            format!(
                "{plane}\nmotion = {{ cache = \"plane.pc2\", fps = 24.0, keys = [{{ t = 0.0, \
                 translate = [0.0, 0.0, 0.0] }}] }}"
            ),
            "",
            vec!["collider[0].motion.cache", "not both"],
        ),
        (
            format!("{plane}\nmotion = {{ cache = \"plane.pc2\" }}"),
            "",
            vec!["collider[0].motion.fps", "frame rate"],
        ),
        (
            "shape = { kind = \"sphere\", center = [0.0, 0.0, 0.0], radius = 0.1 }\n\
             motion = { cache = \"plane.pc2\", fps = 24.0 }"
                .to_string(),
            "",
            vec![
                "collider[0].motion.cache",
                "only a mesh collider can deform",
            ],
        ),
        (
            "shape = { kind = \"mesh\", path = \"torn.obj\" }\n\
             motion = { cache = \"torn.pc2\", fps = 24.0 }"
                .to_string(),
            "",
            vec!["torn.pc2", "vertices 3 and 5", "sample 1", "tear"],
        ),
        (
            plane.to_string(),
            "pin_motion = { cache = \"plane.pc2\", fps = 24.0 }",
            vec!["body[0]", ".pin_motion", "give `pins`"],
        ),
        (
            plane.to_string(),
            "pins = [0]\npin_motion = { cache = \"plane.pc2\", fps = 24.0 }",
            vec!["body[0]", ".pin_motion.cache", "4 points", "2 vertices"],
        ),
        (
            format!("{plane}\nmotion = {{ cache = \".\", fps = 24.0 }}"),
            "",
            vec!["collider[0].motion.cache", "a folder"],
        ),
    ];
    for (collider, body, said) in cases {
        let text = scene(&collider, body);
        // The message and every cause under it, as the command line says them.
        let said_all = crate::meshes::build(&text, &dir).unwrap_err();
        for s in said {
            assert!(
                said_all.contains(s),
                "{collider} {body}: '{said_all}' does not say '{s}'"
            );
        }
    }
    // A penalty needs an inside: an open sheet that deforms cannot give one.
    let text = scene(
        &format!("{plane}\nmotion = {{ cache = \"plane.pc2\", fps = 50.0 }}"),
        "",
    )
    .replace(
        r#"kind = "restitution", cr = 0.0, friction = 0.5"#,
        r#"kind = "penalty", kc = 1000.0, dc = 1.0"#,
    );
    let e = hooke_scene::parse_scene(&text, "bad.toml")
        .unwrap()
        .build(&dir)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("collider[0].shape.path") && e.contains("penalty"),
        "{e}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}
