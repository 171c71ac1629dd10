//! The contact model checked from outside: frames exported as OBJ files are read back with
//! tobj, and no cloth triangle may cross a collider triangle or another cloth triangle it
//! shares no corner with. The crossing test (`hooke::report::crossings`, which `hooke
//! report` runs too) is written from signed volumes, independent of the solver's proximity
//! code.

use crate::common::{builtin, root};
use hooke::Sink;
use hooke::export::obj::ObjExport;
use hooke_core::{Integrator, Model, Particles, Simulation, Surface, Vec3, contact::ContactStats};
use hooke_scene::Overrides;
use std::path::{Path, PathBuf};

use hooke::report::crossings::{self, Tri};

/// One exported frame: the cloth triangles with their corner indices, and the colliders'.
pub(crate) struct Frame {
    pub(crate) cloth: Vec<(Tri, [u32; 3])>,
    pub(crate) colliders: Vec<Tri>,
}

fn read_frame(path: &Path) -> Frame {
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ..tobj::LoadOptions::default()
    };
    let (models, _) = tobj::load_obj(path, &options).unwrap();
    let mut frame = Frame {
        cloth: Vec::new(),
        colliders: Vec::new(),
    };
    for m in models {
        let p = &m.mesh.positions;
        let v = |i: u32| {
            let i = 3 * i as usize;
            Vec3::new(p[i], p[i + 1], p[i + 2])
        };
        for f in m.mesh.indices.chunks(3) {
            let t = [v(f[0]), v(f[1]), v(f[2])];
            if m.name.starts_with("body:") {
                frame.cloth.push((t, [f[0], f[1], f[2]]));
            } else {
                assert!(m.name.starts_with("collider:"), "{}", m.name);
                frame.colliders.push(t);
            }
        }
    }
    frame
}

/// Crossings in one frame: (cloth–collider, cloth–cloth) pair counts.
pub(crate) fn crossings(frame: &Frame) -> (usize, usize) {
    crossings::count(&frame.cloth, &frame.colliders)
}

/// Runs built-in `name` with `overrides` to its end, exporting every frame into a fresh
/// folder named with `tag`.
fn export_run(name: &str, overrides: &Overrides, tag: &str) -> (PathBuf, u64) {
    export_scene(builtin(name, overrides), &format!("{name}-{tag}"))
}

/// Runs `scene` to its end, exporting every frame into a fresh folder named with `tag`.
fn export_scene(mut scene: hooke_scene::Scene, tag: &str) -> (PathBuf, u64) {
    let dir = std::env::temp_dir().join(format!(
        "hooke-contact-{}-{}",
        tag.replace(['/', '.'], "_"),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let mut export = ObjExport::new(&dir, &scene).unwrap();
    export.frame(0, &scene).unwrap();
    let frames = scene.steps / scene.every;
    for f in 1..=frames {
        let every = scene.every;
        scene.simulation.advance(every).unwrap();
        export.frame(f, &scene).unwrap();
    }
    (dir, frames)
}

fn assert_no_crossings(name: &str, table: Option<&str>) {
    let overrides = Overrides {
        table: table.map(|t| t.parse().unwrap()),
        ..Overrides::default()
    };
    assert_no_crossings_with(name, &overrides, table.unwrap_or("default"));
}

/// [`assert_no_crossings`] for built-in `name` under `overrides`; returns the last frame.
pub(crate) fn assert_no_crossings_with(name: &str, overrides: &Overrides, tag: &str) -> Frame {
    let (dir, frames) = export_run(name, overrides, tag);
    frames_never_cross(&dir, frames, &format!("{name} {tag}"))
}

/// [`assert_no_crossings`] for a built scene; returns the last frame.
pub(crate) fn assert_scene_never_crosses(scene: hooke_scene::Scene, tag: &str) -> Frame {
    let (dir, frames) = export_scene(scene, tag);
    frames_never_cross(&dir, frames, tag)
}

/// Reads frames `0..=frames` of `dir`, asserts none crosses, removes `dir` and returns the
/// last frame.
fn frames_never_cross(dir: &Path, frames: u64, what: &str) -> Frame {
    let mut last = None;
    let mut bad = Vec::new();
    for f in 0..=frames {
        let frame = read_frame(&dir.join(format!("frame-{f:05}.obj")));
        assert!(!frame.cloth.is_empty() && !frame.colliders.is_empty());
        let (c, s) = crossings(&frame);
        if c + s > 0 {
            bad.push(format!(
                "frame {f}: {c} cloth-collider, {s} cloth-cloth crossings"
            ));
        }
        last = Some(frame);
    }
    std::fs::remove_dir_all(dir).unwrap();
    assert!(
        bad.is_empty(),
        "{what}: {} of {} frames cross:\n{}",
        bad.len(),
        frames + 1,
        bad.join("\n")
    );
    last.unwrap()
}

#[test]
fn cloth_on_the_round_mesh_table_never_crosses() {
    assert_no_crossings("cloth-table", None);
}

#[test]
fn cloth_on_the_analytic_cylinder_never_crosses() {
    assert_no_crossings("cloth-table", Some("cylinder"));
}

#[test]
fn cloth_on_the_square_table_never_crosses() {
    let square = root().join("assets/meshes/square-table.obj");
    assert_no_crossings("cloth-table", Some(square.to_str().unwrap()));
}

#[test]
fn the_cloth_pile_never_crosses_itself_or_the_ground() {
    assert_no_crossings("cloth-pile", None);
}

/// The checker itself: it sees two triangles through each other, and no crossing between
/// parallel ones or ones apart.
#[test]
fn the_crossing_check_sees_crossings() {
    let flat: Tri = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let through: Tri = [
        Vec3::new(0.2, -0.5, 0.2),
        Vec3::new(0.2, 0.5, 0.2),
        Vec3::new(0.3, 0.5, 0.3),
    ];
    let above = flat.map(|p| p + Vec3::new(0.0, 0.004, 0.0));
    assert!(crossings::triangles_cross(&flat, &through));
    assert!(!crossings::triangles_cross(&flat, &above));
    assert!(!crossings::triangles_cross(
        &above,
        &through.map(|p| p + Vec3::new(5.0, 0.0, 0.0))
    ));
}

/// Two particles' sheets: a 3-particle triangle at rest and one particle moving straight at
/// its middle. After the step the particle is a thickness from the triangle, momentum is
/// what it was, and kinetic energy did not grow.
#[test]
fn a_particle_against_a_sheet_keeps_the_thickness_momentum_and_no_new_energy() {
    let h = 0.005;
    let mut p = Particles::default();
    for x in [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.3, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.3),
    ] {
        p.push(x, Vec3::zeros(), 0.1);
    }
    // A second surface: one triangle far away, whose first corner heads for the sheet.
    p.push(Vec3::new(0.1, 0.006, 0.1), Vec3::new(0.3, -2.0, 0.1), 0.05);
    p.push(Vec3::new(0.1, 0.5, 0.1), Vec3::zeros(), 0.05);
    p.push(Vec3::new(0.1, 0.5, 0.4), Vec3::zeros(), 0.05);
    let surface = |range: std::ops::Range<usize>, tri: [u32; 3]| Surface {
        particles: range,
        triangles: vec![tri],
        thickness: h,
        self_collision: true,
        friction: 0.3,
    };
    let model = Model {
        surfaces: vec![surface(0..3, [0, 1, 2]), surface(3..6, [3, 4, 5])],
        ..Model::default()
    };
    let momentum = |p: &Particles| {
        p.v.iter()
            .zip(&p.mass)
            .fold(Vec3::zeros(), |m, (v, mass)| m + v * *mass)
    };
    let kinetic = |p: &Particles| {
        p.v.iter()
            .zip(&p.mass)
            .map(|(v, m)| 0.5 * m * v.norm_squared())
            .sum::<f64>()
    };
    let (m0, k0) = (momentum(&p), kinetic(&p));
    let mut sim = Simulation::new(p, model, Integrator::Symplectic, 1e-3);
    sim.step().unwrap();
    let q = sim.particles();
    // The particle ended the step on the sheet's side, a thickness from its (now slightly
    // tilted) plane, to a micrometre.
    let n = (q.x[1] - q.x[0]).cross(&(q.x[2] - q.x[0])).normalize();
    let gap = (q.x[3] - q.x[0]).dot(&n).abs();
    assert!(q.x[3].y > q.x[0].y, "the particle went through");
    assert!((gap - h).abs() < 1e-6, "gap {gap}");
    assert!(
        (momentum(q) - m0).norm() < 1e-14,
        "{} vs {}",
        momentum(q),
        m0
    );
    assert!(kinetic(q) < k0, "kinetic {} -> {}", k0, kinetic(q));
    // They no longer approach each other: the sheet's velocity at the point under the
    // particle matches the particle's along the normal.
    let w = hooke_core::contact::proximity::point_triangle(&q.x[3], &q.x[0], &q.x[1], &q.x[2]);
    let under = q.v[0] * w[0] + q.v[1] * w[1] + q.v[2] * w[2];
    let closing = (q.v[3] - under).dot(&n);
    assert!(closing > -1e-12, "{closing}");
    let stats: ContactStats = sim.contact_stats();
    assert!(stats.proximities >= 1);
}

/// A resting cloth lies a thickness above the ground, never on it: no z-fighting.
#[test]
fn cloth_rests_a_thickness_above_the_ground() {
    let mut scene = builtin("cloth-pile", &Overrides::default());
    let h = scene.bodies[0].thickness;
    assert_eq!(h, hooke_core::DEFAULT_CLOTH_THICKNESS);
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    let lowest = crate::common::lowest(&scene);
    assert!(
        (lowest - h).abs() < 1e-4,
        "lowest particle at {lowest} m, thickness {h} m"
    );
}

/// The contact phase skips a candidate pair while its particles' motion since it was last
/// tested cannot have closed its distance to the thickness, and a particle's check against
/// a collider while its path since the last check cannot have reached it. Testing every
/// pair and every particle at every step instead must give the same bits: on cloth falling
/// onto each table and onto itself, on the flapping flag, and on a finer cloth whose pairs
/// are mostly far apart.
#[test]
fn skipping_what_cannot_touch_changes_no_bit() {
    let finer = |spec: &mut hooke_scene::SceneSpec| {
        let body = &mut spec.bodies[0];
        if let hooke_scene::spec::ShapeSpec::Grid { size, spacing } = &mut body.shape {
            *size = [48, 48];
            *spacing = hooke_scene::spec::Positive::of(1.6 / 47.0);
        }
        body.mass = Some(hooke_scene::spec::Positive::of(0.4 / (48.0 * 48.0)));
        body.pins = Default::default();
    };
    let cases: [(&str, Option<&str>, bool, u64); 5] = [
        ("cloth-table", None, false, 6000),
        ("cloth-table", Some("cylinder"), false, 6000),
        ("cloth-pile", None, false, 6000),
        ("flag", None, false, 3000),
        ("cloth-table", None, true, 4000),
    ];
    for (name, table, fine, steps) in cases {
        let overrides = Overrides {
            table: table.map(|t| t.parse().unwrap()),
            ..Overrides::default()
        };
        let run = |exhaustive: bool| {
            let mut spec = hooke_scene::builtin::builtin(name).unwrap();
            overrides.apply(&mut spec).unwrap();
            if fine {
                finer(&mut spec);
            }
            let mut scene = spec.build(&root().join("assets/scenes")).unwrap();
            scene.simulation.set_exhaustive_contacts(exhaustive);
            scene.simulation.advance(steps).unwrap();
            let p = scene.simulation.particles();
            (p.x.clone(), p.v.clone())
        };
        let (skipping, exhaustive) = (run(false), run(true));
        let bits = |v: &[Vec3]| {
            v.iter()
                .flat_map(|p| [p.x, p.y, p.z].map(f64::to_bits))
                .collect::<Vec<_>>()
        };
        assert!(
            bits(&skipping.0) == bits(&exhaustive.0) && bits(&skipping.1) == bits(&exhaustive.1),
            "{name} {table:?} fine={fine}: skipping pairs changed the state after {steps} steps"
        );
    }
}

/// Every collider a step lets a surface through is said at that step, not only the first
/// in the scene's order: cloth-table with its round table given twice, one over the other,
/// under implicit Euler at 1/60 s (as below). Before, the second table was never named, as
/// the first was crossed at every step the second was.
#[test]
fn each_collider_a_large_step_lets_the_cloth_through_is_said_at_its_first_step() {
    let overrides = Overrides {
        integrator: Some(Integrator::Implicit),
        dt: Some(1.0 / 60.0),
        duration: Some(1.0),
        ..Overrides::default()
    };
    let mut spec = hooke_scene::builtin::builtin("cloth-table").unwrap();
    overrides.apply(&mut spec).unwrap();
    spec.colliders.push(spec.colliders[1].clone());
    let mut scene = spec.build(&root().join("assets/scenes")).unwrap();
    let mut first = [None; 3];
    for _ in 0..scene.steps {
        scene.simulation.step().unwrap();
        for notice in scene.simulation.take_notices() {
            if let hooke_core::Through::Collider(k) = notice.through {
                first[k].get_or_insert(notice.step);
            }
        }
    }
    assert!(first[1].is_some(), "{first:?}");
    assert_eq!(first[1], first[2], "{first:?}");
}

/// Issue 54: implicit Euler at 1/60 s lets the cloth through the round table (its contacts
/// come after a step that moves the cloth centimetres). It may not do so in silence: the
/// crossing watch names the table at the first step after which an exported frame crosses
/// it, by the signed-volume test, which knows nothing of the solver's.
#[test]
fn implicit_at_a_frame_per_step_says_when_the_cloth_first_crosses_the_table() {
    let overrides = Overrides {
        integrator: Some(Integrator::Implicit),
        dt: Some(1.0 / 60.0),
        every: Some(1),
        duration: Some(1.0),
        ..Overrides::default()
    };
    let mut scene = builtin("cloth-table", &overrides);
    let dir = std::env::temp_dir().join(format!("hooke-contact-watch-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut export = ObjExport::new(&dir, &scene).unwrap();
    export.frame(0, &scene).unwrap();
    let mut first_crossing = None;
    let mut first_notice = None;
    for f in 1..=scene.steps {
        scene.simulation.step().unwrap();
        if first_notice.is_none() {
            first_notice = scene.simulation.take_notices().into_iter().next();
        }
        export.frame(f, &scene).unwrap();
        let (c, _) = crossings(&read_frame(&dir.join(format!("frame-{f:05}.obj"))));
        if c > 0 && first_crossing.is_none() {
            first_crossing = Some(f);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
    let crossed = first_crossing.expect("the cloth crossed the table at 1/60 s");
    let notice = first_notice.expect("a crossing was said");
    assert_eq!(notice.step, crossed, "{notice:?}");
    assert_eq!(
        notice.through,
        hooke_core::Through::Collider(1),
        "{notice:?}"
    );
    assert!(
        matches!(
            notice.cause,
            hooke_core::Cause::LargeStep {
                integrator: Integrator::Implicit,
                ..
            }
        ),
        "{notice:?}"
    );
}
