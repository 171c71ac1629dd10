//! The seven built-in scenes: shipped files equal the built-ins, every scene runs stable to its
//! end, and its trajectory is locked by a snapshot.

use crate::common::{builtin, root, round_sig};
use hooke_core::Summary;
use hooke_scene::builtin::BUILTINS;
use hooke_scene::{Overrides, Scene, Topology};
use std::fmt::Write;

#[test]
fn every_shipped_scene_file_equals_its_builtin() {
    for (name, make) in BUILTINS {
        let path = root().join(format!("assets/scenes/{name}.toml"));
        let spec = hooke_scene::load_scene(&path).unwrap();
        assert_eq!(
            spec,
            make(),
            "{} differs from the built-in; regenerate it with `hooke scene {name}`",
            path.display()
        );
    }
}

#[test]
fn printed_scenes_read_back_identical() {
    for (name, make) in BUILTINS {
        let text = hooke_scene::to_toml(&make());
        assert_eq!(
            hooke_scene::parse_scene(&text, name).unwrap(),
            make(),
            "{name}"
        );
    }
}

/// The particles a snapshot follows, documented per topology: the ends of a chain, the four
/// corners and the centre of a cloth, the eight corners of a lattice, every explicit point.
pub fn tracked(scene: &Scene) -> Vec<usize> {
    let mut out = Vec::new();
    for body in &scene.bodies {
        let s = body.range.start;
        let local: Vec<usize> = match body.topology {
            Topology::Chain => vec![0, body.range.len() / 2, body.range.len() - 1],
            Topology::Grid([a, b]) => vec![0, b - 1, (a - 1) * b, a * b - 1, (a / 2) * b + b / 2],
            Topology::Lattice([a, b, c]) => {
                let mut v = Vec::new();
                for i in [0, a - 1] {
                    for j in [0, b - 1] {
                        for k in [0, c - 1] {
                            v.push((i * b + j) * c + k);
                        }
                    }
                }
                v
            }
            Topology::Points => (0..body.range.len()).collect(),
            // The first, middle and last particle of a body made from a mesh.
            Topology::Mesh | Topology::Solid => {
                let n = body.range.len();
                vec![0, n / 2, n - 1]
            }
        };
        out.extend(local.into_iter().map(|i| s + i));
    }
    out
}

/// Positions of the tracked particles and the frame summary at a few frames, rounded to six
/// significant digits (values under a nanounit are zeroed, see [`crate::common::round_sig`]):
/// enough to catch any change to the physics, while the last bits of libm's sin/cos (used to
/// place rotated bodies) or of the force summation order cannot flip a digit.
pub fn trajectory_report(scene: &mut Scene, checkpoints: &[u64]) -> String {
    let ids = tracked(scene);
    let mut out = String::new();
    let r = |x: f64| round_sig(x, 6);
    for &step in checkpoints {
        let sim = &mut scene.simulation;
        sim.advance(step - sim.steps()).unwrap();
        let s = Summary::of(sim.model(), sim.particles());
        let _ = writeln!(out, "step {step} t={}", r(sim.time()));
        let _ = writeln!(
            out,
            "  kinetic {} potential {} max_speed {}",
            r(s.kinetic),
            r(s.potential),
            r(s.max_speed)
        );
        let _ = writeln!(
            out,
            "  bbox [{}, {}, {}] .. [{}, {}, {}]",
            r(s.min.x),
            r(s.min.y),
            r(s.min.z),
            r(s.max.x),
            r(s.max.y),
            r(s.max.z)
        );
        for &i in &ids {
            let x = sim.particles().x[i];
            let _ = writeln!(out, "  p{i}: {} {} {}", r(x.x), r(x.y), r(x.z));
        }
    }
    out
}

/// A built-in's trajectory at its start, quarter, half and end, against its snapshot.
fn scene_snapshot(name: &str) {
    let mut scene = builtin(name, &Overrides::default());
    let n = scene.steps;
    let report = trajectory_report(&mut scene, &[0, n / 4, n / 2, n]);
    insta::assert_snapshot!(format!("scene_{name}"), report);
}

/// One test per built-in, so that one scene's mismatch does not hide another's.
macro_rules! scene_snapshots {
    ($($test:ident => $name:literal),* $(,)?) => {
        $(
            #[test]
            fn $test() {
                scene_snapshot($name);
            }
        )*

        /// Every built-in has its snapshot test above.
        #[test]
        fn every_builtin_has_a_snapshot_test() {
            let tested = [$($name),*];
            let builtins: Vec<&str> = BUILTINS.iter().map(|(n, _)| *n).collect();
            assert_eq!(builtins, tested);
        }
    };
}

scene_snapshots! {
    snapshot_single_spring => "single-spring",
    snapshot_chain => "chain",
    snapshot_jello_cube => "jello-cube",
    snapshot_hanging_cloth => "hanging-cloth",
    snapshot_cloth_table => "cloth-table",
    snapshot_cloth_pile => "cloth-pile",
    snapshot_flag => "flag",
    snapshot_tablecloth => "tablecloth",
    snapshot_puck_sweep => "puck-sweep",
}
