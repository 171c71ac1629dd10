//! Crease cases for block descent's self-contact (docs/physics.md §4.1, "What self-contact
//! skips"): the detection skips the pairs a cloth's own structure holds apart, so a crease
//! is where a crossing could hide. Each case is run at one step per 60 Hz frame, every step
//! exported, and every frame read back with the crossing test that is independent of the
//! solver (`hooke::report::crossings`): cloth pushed into a cup by a ball, a sheet folded
//! tight over itself by its keyed edge, and a hanging sheet twisted one and a half turns.
//! The pile and the stack of three cloths are `large_steps.rs`'s. Where a crease is tighter
//! than the skipped pairs (a sleeve Blender made, landing on its folds), the run says so at
//! every step a skipped pair has crossed, and at no other.

use crate::common::root;
use crate::contact::assert_scene_never_crosses;
use hooke::report::crossings::{Tri, cloth_pairs};
use hooke_core::Through;
use hooke_scene::Scene;

/// An `n`×`n` cotton-weight sheet `size` m wide (5 mm thickness, self-collision on) under
/// block descent at 1/60 s for `duration` s, with `extra` TOML (pins, colliders) added to
/// its body and scene.
fn sheet(
    n: usize,
    size: f64,
    origin: [f64; 3],
    duration: f64,
    (body, rest): (&str, &str),
) -> Scene {
    let text = format!(
        r#"
name = "crease"
[simulation]
integrator = "vbd"
dt = 0.016666666666666666
duration = {duration}
every = 1
gravity = [0.0, -9.81, 0.0]
drag = 0.002
[[body]]
name = "sheet"
mass = {mass}
origin = [{}, {}, {}]
thickness = 0.005
self_collision = true
friction = 0.3
{body}
[body.shape]
kind = "grid"
size = [{n}, {n}]
spacing = {spacing}
[body.springs.structural]
ks = 300.0
kd = 0.02
[body.springs.shear]
ks = 150.0
kd = 0.02
[body.springs.bend]
ks = 5.0
kd = 0.005
{rest}
"#,
        origin[0],
        origin[1],
        origin[2],
        mass = 0.12 / (n * n) as f64,
        spacing = size / (n - 1) as f64,
    );
    hooke_scene::parse_scene(&text, "crease.toml")
        .unwrap()
        .build(&root().join("assets/scenes"))
        .unwrap()
}

/// The ground, with friction.
const GROUND: &str = r#"
[[collider]]
shape = { kind = "ground", height = 0.0 }
response = { kind = "restitution", cr = 0.0, friction = 0.5 }
"#;

/// The highest point of the cloth in the last frame, and its lowest.
fn heights(frame: &crate::contact::Frame) -> (f64, f64) {
    let ys = frame.cloth.iter().flat_map(|(t, _)| t.iter().map(|p| p.y));
    ys.fold((f64::MIN, f64::MAX), |(hi, lo), y| (hi.max(y), lo.min(y)))
}

/// An open cup 0.3 m wide and deep (a floor and four walls of a thin mesh), written as an
/// OBJ file into the temporary folder; its path.
fn cup() -> std::path::PathBuf {
    let w = 0.15;
    let corners = [[-w, 0.0, -w], [w, 0.0, -w], [w, 0.0, w], [-w, 0.0, w]];
    let mut obj = String::new();
    for y in [0.0, 0.3] {
        for [x, _, z] in corners {
            obj += &format!("v {x} {y} {z}\n");
        }
    }
    // The floor (facing up, into the cup), then each wall as a quad.
    obj += "f 1 4 3 2\n";
    for k in 0..4 {
        let (a, b) = (k + 1, (k + 1) % 4 + 1);
        obj += &format!("f {a} {b} {} {}\n", b + 4, a + 4);
    }
    let path = std::env::temp_dir().join(format!("hooke-crease-cup-{}.obj", std::process::id()));
    std::fs::write(&path, obj).unwrap();
    path
}

/// A 0.6 m sheet lying over an open cup 0.3 m wide, pushed to near its floor by a ball
/// 0.24 m across: the cloth is drawn in over the rim and folds on itself between the ball
/// and the walls.
#[test]
fn cloth_pushed_into_a_cup_by_a_ball_never_crosses() {
    let cup = cup();
    let colliders = format!(
        r#"{GROUND}
[[collider]]
shape = {{ kind = "mesh", path = "{}" }}
response = {{ kind = "restitution", cr = 0.0, friction = 0.3 }}
[[collider]]
shape = {{ kind = "sphere", center = [0.0, 0.45, 0.0], radius = 0.12 }}
response = {{ kind = "restitution", cr = 0.0, friction = 0.3 }}
motion = {{ keys = [{{ t = 0.3, translate = [0.0, 0.0, 0.0] }}, {{ t = 1.8, translate = [0.0, -0.3, 0.0] }}] }}
"#,
        cup.display()
    );
    let scene = sheet(30, 0.6, [-0.3, 0.31, -0.3], 2.5, ("", &colliders));
    let last = assert_scene_never_crosses(scene, "crease-cup");
    std::fs::remove_file(&cup).unwrap();
    // Pushed in under the ball (whose bottom ends 3 cm above the floor), its edges still
    // over the rim.
    let (hi, lo) = heights(&last);
    assert!(lo < 0.06 && hi > 0.2, "cloth spans {lo}..{hi} m");
}

/// A 0.4 m sheet lying on the ground, its first row keyed up, over and down onto its last:
/// folded tight on itself, two layers a thickness apart along the crease.
#[test]
fn a_sheet_folded_tight_on_itself_never_crosses() {
    let pins = r#"
pins = { box = [[-0.01, -0.01, -0.01], [0.41, 0.01, 0.01]] }
pin_motion = { keys = [{ t = 0.0, translate = [0.0, 0.0, 0.0] }, { t = 0.8, translate = [0.0, 0.12, 0.2] }, { t = 1.6, translate = [0.0, 0.012, 0.39] }] }
"#;
    let scene = sheet(24, 0.4, [0.0, 0.0055, 0.0], 2.5, (pins, GROUND));
    let last = assert_scene_never_crosses(scene, "crease-fold");
    // Folded: two layers, the top one resting on the bottom one.
    let (hi, _) = heights(&last);
    assert!(hi < 0.05, "the fold stands {hi} m high");
}

/// A 0.4 m sheet hanging from its top row, which turns one and a half times about the
/// vertical through its middle in 2 s: the sheet winds on itself.
#[test]
fn a_hanging_sheet_twisted_on_itself_never_crosses() {
    let pins = r#"
pins = { box = [[-0.01, -0.01, -0.01], [0.41, 0.01, 0.01]] }
pin_motion = { keys = [{ t = 0.0, translate = [0.0, 0.0, 0.0] }, { t = 0.66, translate = [0.0, 0.0, 0.0], rotate = [0.0, 180.0, 0.0] }, { t = 1.33, translate = [0.0, 0.0, 0.0], rotate = [0.0, 360.0, 0.0] }, { t = 2.0, translate = [0.0, 0.0, 0.0], rotate = [0.0, 540.0, 0.0] }] }
"#;
    // Hung in the x-y plane: turned 90° about x, its first row on top.
    let pins = format!("rotate = [90.0, 0.0, 0.0]\n{pins}");
    let scene = sheet(24, 0.4, [-0.2, 1.0, 0.0], 2.5, (&pins, GROUND));
    assert_scene_never_crosses(scene, "crease-twist");
}

/// A sleeve Blender made (`tests/fixtures/blender-sleeve.obj`, by `check_blender_mesh.py
/// make-sleeve`: an open cylinder 12 cm across and 60 cm long, 32 sides in 12 rings, its
/// 4:1 triangles from 11.8 to 51 mm), of silk, dropped 0.5 m onto the ground with friction
/// under `integrator` at 1/60 s for 1 s.
pub(crate) fn blender_sleeve(integrator: &str) -> Scene {
    let dir = root().join("tests/fixtures");
    let text = format!(
        r#"
name = "sleeve"
[simulation]
integrator = "{integrator}"
dt = 0.016666666666666666
duration = 1.0
every = 1
[[body]]
name = "sleeve"
self_collision = true
shape = {{ kind = "mesh", path = "blender-sleeve.obj" }}
material = {{ preset = "silk" }}
[[collider]]
shape = {{ kind = "ground", height = 0.0 }}
response = {{ kind = "restitution", cr = 0.0, friction = 0.5 }}
"#
    );
    crate::meshes::build(&text, &dir).unwrap()
}

/// Each face of `faces` (triangles) at positions `x`, with its corners, as the crossing
/// checker takes them.
fn triangles_at(faces: &[Vec<u32>], x: &[hooke_core::Vec3]) -> Vec<(Tri, [u32; 3])> {
    faces
        .iter()
        .map(|f| ([0, 1, 2].map(|k| x[f[k] as usize]), [f[0], f[1], f[2]]))
        .collect()
}

/// What [`step_watching_folds`] saw: the independent checker's crossings after each step,
/// split by whether the pair is one self-contact skips, and what the run said.
pub(crate) struct Folds {
    /// Crossing pairs farther apart at rest than the skipped pairs' reach, one line each.
    pub(crate) unskipped: Vec<String>,
    /// The most skipped pairs crossed after one step.
    pub(crate) most: usize,
    /// Steps after which a skipped pair was crossed.
    pub(crate) steps: u64,
    /// Steps at which the run's word (a notice of the surface through itself) and the
    /// checker disagree, one line each.
    pub(crate) disagree: Vec<String>,
}

impl Folds {
    /// No pair crossed but those self-contact skips, and the run said so at exactly the
    /// steps they did.
    pub(crate) fn assert_only_skipped_pairs_cross_and_are_said(&self) {
        assert!(self.unskipped.is_empty(), "{}", self.unskipped.join("\n"));
        assert!(self.disagree.is_empty(), "{}", self.disagree.join("\n"));
    }
}

/// Steps `scene` to its end, calling `each` after every step, and compares after every
/// step the cloth's crossing triangle pairs (the checker independent of the solver) with
/// the run's notices of its first body passing through itself. A crossing pair is counted
/// as skipped when two of its corners were within the skipped pairs' reach at rest.
pub(crate) fn step_watching_folds(scene: &mut Scene, mut each: impl FnMut(&Scene)) -> Folds {
    let faces = scene.bodies[0].faces();
    let rest = scene.simulation.particles().x.clone();
    let reach = scene.simulation.model().self_contact_skip();
    let apart = |a: &[u32], b: &[u32]| {
        let corners = |f: &[u32]| f.iter().map(|&i| rest[i as usize]).collect::<Vec<_>>();
        let (ca, cb) = (corners(a), corners(b));
        ca.iter()
            .flat_map(|p| cb.iter().map(move |q| (p - q).norm()))
            .fold(f64::INFINITY, f64::min)
    };
    let said = |scene: &Scene| -> u64 {
        let tally = scene.simulation.notice_tally();
        let itself = tally
            .iter()
            .find(|(n, _)| matches!(n.through, Through::Itself(_)));
        itself.map_or(0, |(_, steps)| *steps)
    };
    let mut folds = Folds {
        unskipped: Vec::new(),
        most: 0,
        steps: 0,
        disagree: Vec::new(),
    };
    for step in 1..=scene.steps {
        let before = said(scene);
        scene.simulation.step().unwrap();
        each(scene);
        let x = &scene.simulation.particles().x;
        let cloth = triangles_at(&faces, x);
        let mut here = 0;
        for (a, b) in cloth_pairs(&cloth) {
            if apart(&faces[a], &faces[b]) <= reach * (1.0 + 1e-9) {
                here += 1;
            } else {
                folds
                    .unskipped
                    .push(format!("step {step}: triangles {a} and {b}"));
            }
        }
        folds.most = folds.most.max(here);
        folds.steps += u64::from(here > 0);
        let told = said(scene) > before;
        if told != (here > 0) {
            folds.disagree.push(format!(
                "step {step}: {here} skipped pairs crossed, and the run {} so",
                if told { "said" } else { "did not say" }
            ));
        }
    }
    folds
}

/// The same sleeve under block descent, whose creases at the tube's flattened edges are
/// tighter than its skipped pairs (one 11.8 mm ring edge): wherever the checker finds them
/// crossed, the run said so at that step, and nowhere else.
#[test]
fn a_sleeve_folded_tighter_than_the_skipped_pairs_is_said_at_every_step() {
    let mut scene = blender_sleeve("vbd");
    let folds = step_watching_folds(&mut scene, |_| {});
    folds.assert_only_skipped_pairs_cross_and_are_said();
    eprintln!(
        "crossed skipped pairs on {} steps, at most {} a step",
        folds.steps, folds.most
    );
}

/// A surface that does not collide with itself is let through itself by design: the same
/// sleeve with self-collision off, beside a patch that has it on (so that the pairs of
/// self-contact are listed), falls through its own folds under Newton, and the run says
/// nothing of it (it said so at step 20 while the watch still looked at such a surface).
#[test]
fn a_surface_without_self_collision_is_not_said_through_itself() {
    let dir = root().join("tests/fixtures");
    let text = r#"
name = "two"
[simulation]
integrator = "newton"
dt = 0.016666666666666666
duration = 1.0
every = 1
[[body]]
name = "sleeve"
self_collision = false
shape = { kind = "mesh", path = "blender-sleeve.obj" }
material = { preset = "silk" }
[[body]]
name = "patch"
origin = [2.0, 0.1, 0.0]
self_collision = true
shape = { kind = "grid", size = [4, 4], spacing = 0.05 }
material = { preset = "cotton" }
[[collider]]
shape = { kind = "ground", height = 0.0 }
response = { kind = "restitution", cr = 0.0, friction = 0.5 }
"#;
    let mut scene = crate::meshes::build(text, &dir).unwrap();
    let faces = scene.bodies[0].faces();
    let mut crossed = 0;
    for _ in 0..scene.steps {
        scene.simulation.step().unwrap();
        let x = &scene.simulation.particles().x;
        let cloth = triangles_at(&faces, x);
        crossed += usize::from(!cloth_pairs(&cloth).is_empty());
    }
    assert!(
        crossed > 10,
        "the sleeve crossed itself after only {crossed} steps"
    );
    let said: Vec<_> = scene.simulation.notice_tally().to_vec();
    assert!(said.is_empty(), "{said:?}");
}

/// Whether two triangles the checker finds crossed lie in one plane to rounding (every
/// corner of each within 1e-9 m of the other's plane): a sheet still flat, not a crossing.
fn flat(a: &Tri, b: &Tri) -> bool {
    let near = |t: &Tri, of: &Tri| {
        let n = (of[1] - of[0]).cross(&(of[2] - of[0])).normalize();
        t.iter().all(|p| n.dot(&(p - of[0])).abs() <= 1e-9)
    };
    near(a, b) || near(b, a)
}

/// Implicit Euler resolves contacts after its step, and at 4 ms on the cloth pile (where
/// `hooke check` asks for under 0.47 ms) a step can close two layers by more than their
/// 5 mm thickness: the pile folds through itself. The run says so at every step after
/// which the checker independent of the solver finds a pair crossed that was not before,
/// the first said at the first such step, and at no step after which nothing crosses
/// (docs/physics.md §3.5, "Layers after a large step").
#[test]
fn layers_that_a_large_implicit_step_lets_through_each_other_are_said_at_the_step() {
    let overrides = hooke_scene::Overrides {
        integrator: Some(hooke_core::Integrator::Implicit),
        dt: Some(0.004),
        duration: Some(1.0),
        ..Default::default()
    };
    let mut scene = crate::common::builtin("cloth-pile", &overrides);
    let faces = scene.bodies[0].faces();
    let said = |scene: &Scene| -> u64 {
        let tally = scene.simulation.notice_tally();
        tally
            .iter()
            .filter(|(n, _)| matches!(n.cause, hooke_core::Cause::Layers { .. }))
            .map(|(_, steps)| *steps)
            .sum()
    };
    let (mut before, mut first, mut disagree) = (Vec::new(), None, Vec::new());
    for step in 1..=scene.steps {
        let told_before = said(&scene);
        scene.simulation.step().unwrap();
        let cloth = triangles_at(&faces, &scene.simulation.particles().x);
        let now: Vec<_> = cloth_pairs(&cloth)
            .into_iter()
            .filter(|&(a, b)| !flat(&cloth[a].0, &cloth[b].0))
            .collect();
        let fresh = now.iter().filter(|p| !before.contains(*p)).count();
        let told = said(&scene) > told_before;
        if fresh > 0 {
            first.get_or_insert(step);
        }
        if (fresh > 0 && !told) || (told && now.is_empty()) {
            disagree.push(format!(
                "step {step}: {fresh} pairs newly crossed ({} in all), and the run {} so",
                now.len(),
                if told { "said" } else { "did not say" }
            ));
        }
        before = now;
    }
    assert!(disagree.is_empty(), "{}", disagree.join("\n"));
    let first = first.expect("the pile folds through itself at 4 ms steps");
    let tally = scene.simulation.notice_tally();
    let (notice, _) = tally
        .iter()
        .find(|(n, _)| matches!(n.cause, hooke_core::Cause::Layers { .. }))
        .unwrap();
    assert_eq!(notice.step, first, "said at the first step that crossed");
    assert_eq!(notice.through, Through::Itself(0));
    eprintln!(
        "first crossed at step {first}; said on {} steps",
        said(&scene)
    );
}

/// Three cloths dropped in a stack (`assets/examples/cloth-stack.toml`) under implicit
/// Euler at 1/60 s pass through each other and themselves: each pair of bodies (a body and
/// itself included) is said at the first step the independent checker finds it crossed
/// (or the step before, where an edge passed exactly through the edge of two triangles),
/// never later, and no pair is said that the checker does not find.
#[test]
fn each_pair_of_cloths_a_large_step_lets_through_each_other_is_said_at_its_first_step() {
    let overrides = hooke_scene::Overrides {
        integrator: Some(hooke_core::Integrator::Implicit),
        dt: Some(1.0 / 60.0),
        duration: Some(1.0),
        ..Default::default()
    };
    let path = root().join("assets/examples/cloth-stack.toml");
    let mut spec = hooke_scene::load_scene(&path).unwrap();
    overrides.apply(&mut spec).unwrap();
    let mut scene = spec.build(path.parent().unwrap()).unwrap();
    // Every body's triangles with particle numbers, and the body of each.
    let (mut faces, mut body) = (Vec::new(), Vec::new());
    for (k, b) in scene.bodies.iter().enumerate() {
        let offset = b.range.start as u32;
        for f in b.faces() {
            faces.push(f.iter().map(|&i| i + offset).collect::<Vec<_>>());
            body.push(k);
        }
    }
    let mut checker = std::collections::BTreeMap::new();
    for step in 1..=scene.steps {
        scene.simulation.step().unwrap();
        let cloth = triangles_at(&faces, &scene.simulation.particles().x);
        for (a, b) in cloth_pairs(&cloth) {
            if !flat(&cloth[a].0, &cloth[b].0) {
                let pair = (body[a].min(body[b]), body[a].max(body[b]));
                checker.entry(pair).or_insert(step);
            }
        }
    }
    let said: std::collections::BTreeMap<_, _> = scene
        .simulation
        .notice_tally()
        .iter()
        .filter_map(|(n, _)| match n.through {
            Through::Itself(s) => Some(((s, s), n.step)),
            Through::Surfaces(a, b) => Some(((a, b), n.step)),
            Through::Collider(_) => None,
        })
        .collect();
    assert!(checker.len() >= 3, "the stack crosses: {checker:?}");
    // The checker counts an edge through a triangle's inside: an edge through the edge two
    // triangles share (cloth-1 through itself at step 52, where the inside test gives 0.0)
    // it finds when the edge has moved off it, a step later.
    let pairs =
        |m: &std::collections::BTreeMap<(usize, usize), u64>| m.keys().copied().collect::<Vec<_>>();
    assert_eq!(
        pairs(&said),
        pairs(&checker),
        "pairs of bodies crossed: said, found"
    );
    for (pair, found) in &checker {
        let told = said[pair];
        assert!(
            told == *found || told + 1 == *found,
            "bodies {pair:?}: said at step {told}, found crossed from step {found}"
        );
    }
    eprintln!("(bodies) → first step said: {said:?}; found: {checker:?}");
}
