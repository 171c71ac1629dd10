//! Jello worlds: the five public worlds read, run and are locked by snapshots; bad files are
//! refused with the line and what was expected; write → read is the identity.

use crate::common::root;
use crate::scenes::trajectory_report;
use hooke_scene::world::{World, load_world, parse_world};
use std::path::Path;

pub(crate) const WORLDS: [&str; 5] = ["jello", "gravity", "moveLeft", "rotate", "skewedCorner"];

pub(crate) fn world(name: &str) -> World {
    load_world(&root().join(format!("assets/worlds/{name}.w"))).unwrap()
}

#[test]
fn public_worlds_read_with_their_headers() {
    let w = world("rotate");
    assert_eq!(w.integrator, hooke_core::Integrator::Rk4);
    assert_eq!((w.dt, w.every), (0.001, 1));
    assert_eq!(
        (w.k_elastic, w.d_elastic, w.k_collision, w.d_collision),
        (500.0, 0.25, 1000.0, 0.25)
    );
    assert_eq!(w.plane, Some([1.0, -1.0, -1.0, 4.0]));
    assert_eq!(
        (w.resolution, w.field.len(), w.positions.len()),
        (30, 27000, 512)
    );
    assert_eq!(world("moveLeft").plane, None);
}

#[test]
fn a_world_built_in_code_with_bad_values_is_refused_by_name() {
    let mut w = world("jello");
    w.velocities[3].y = f64::NAN;
    let e = w.to_scene("bad").unwrap_err().to_string();
    assert_eq!(
        e,
        "world value velocities[3]: expected a finite number, found NaN"
    );
    let mut w = world("rotate");
    w.k_elastic = -1.0;
    w.plane = Some([1.0, f64::INFINITY, 0.0, 0.0]);
    let e = w.to_scene("bad").unwrap_err().to_string();
    assert!(
        e.starts_with("world value kElastic: expected a finite number >= 0"),
        "{e}"
    );
    w.k_elastic = 1.0;
    let e = w.to_scene("bad").unwrap_err().to_string();
    assert!(
        e.starts_with("world value plane[1]: expected a finite number"),
        "{e}"
    );
}

#[test]
fn worlds_write_and_read_back_identical() {
    for name in WORLDS {
        let w = world(name);
        assert_eq!(
            parse_world(&w.to_text(), Path::new("again.w")).unwrap(),
            w,
            "{name}"
        );
        let scene = w.to_scene(name).unwrap();
        assert_eq!(
            World::from_scene(&scene).unwrap(),
            w,
            "{name} through a scene"
        );
        let toml = hooke_scene::to_toml(&scene);
        assert_eq!(
            hooke_scene::parse_scene(&toml, "w.toml").unwrap(),
            scene,
            "{name} through TOML text"
        );
    }
}

#[test]
fn a_world_has_the_course_springs_and_rest_lengths() {
    let scene = world("skewedCorner")
        .to_scene("skewedCorner")
        .unwrap()
        .build(Path::new("."))
        .unwrap();
    let springs = &scene.simulation.model().springs;
    assert_eq!(springs.len(), 6220);
    // Rest lengths come from the undeformed cube, not the skewed start.
    let r9 = |x: f64| (x * 1e9).round() / 1e9;
    let mut lengths: Vec<f64> = springs.iter().map(|s| r9(s.rest * 7.0)).collect();
    lengths.sort_by(f64::total_cmp);
    lengths.dedup();
    assert_eq!(lengths, vec![1.0, r9(2f64.sqrt()), r9(3f64.sqrt()), 2.0]);
    assert_eq!(scene.simulation.model().gravity, hooke_core::Vec3::zeros());
}

/// jello.w's field is zero everywhere and is left out of the model (the solver skips
/// sampling it); rotate.w's is kept.
#[test]
fn zero_fields_are_left_out_and_others_kept() {
    let model_of = |name: &str| {
        world(name)
            .to_scene(name)
            .unwrap()
            .build(Path::new("."))
            .unwrap()
    };
    let jello = model_of("jello");
    assert!(
        world("jello")
            .field
            .iter()
            .all(|v| *v == hooke_core::Vec3::zeros())
    );
    assert!(jello.simulation.model().field.is_none());
    let rotate = model_of("rotate");
    let field = rotate
        .simulation
        .model()
        .field
        .as_ref()
        .expect("rotate.w has a field");
    assert!(!field.is_zero());
}

/// A public world's trajectory at steps 0, 100, 500 and 1000, against its snapshot.
fn world_snapshot(name: &str) {
    let mut scene = world(name)
        .to_scene(name)
        .unwrap()
        .build(Path::new("."))
        .unwrap();
    let report = trajectory_report(&mut scene, &[0, 100, 500, 1000]);
    insta::assert_snapshot!(format!("world_{name}"), report);
}

/// One test per world, so that one world's mismatch does not hide another's.
macro_rules! world_snapshots {
    ($($test:ident => $name:literal),* $(,)?) => {
        $(
            #[test]
            fn $test() {
                world_snapshot($name);
            }
        )*

        /// Every public world has its snapshot test above.
        #[test]
        fn every_world_has_a_snapshot_test() {
            assert_eq!(WORLDS, [$($name),*]);
        }
    };
}

world_snapshots! {
    snapshot_jello => "jello",
    snapshot_gravity => "gravity",
    snapshot_move_left => "moveLeft",
    snapshot_rotate => "rotate",
    snapshot_skewed_corner => "skewedCorner",
}

fn error(text: &str) -> String {
    parse_world(text, Path::new("bad.w"))
        .unwrap_err()
        .to_string()
}

fn valid_text() -> String {
    world("moveLeft").to_text()
}

/// Replaces line `n` (1-based) of the valid world.
fn with_line(n: usize, line: &str) -> String {
    let mut lines: Vec<String> = valid_text().lines().map(String::from).collect();
    lines[n - 1] = line.to_string();
    lines.join("\n") + "\n"
}

#[test]
fn bad_worlds_are_refused_with_line_and_expectation() {
    let cases: Vec<(String, &str)> = vec![
        (
            with_line(1, "Verlet"),
            "bad.w:1: expected the integrator RK4 or Euler, found 'Verlet'",
        ),
        (
            with_line(2, "-0.001 1"),
            "bad.w:2: expected the step size dt > 0, found -0.001",
        ),
        (
            with_line(2, "0.001 0"),
            "bad.w:2: expected the frame cadence n >= 1, found 0",
        ),
        (
            with_line(3, "500 0.25 abc 0.25"),
            "bad.w:3: expected kCollision (a number), found 'abc'",
        ),
        (
            with_line(4, "0"),
            "bad.w:4: expected the point mass > 0, found 0",
        ),
        (
            with_line(4, "nan"),
            "bad.w:4: expected the point mass as a finite number, found 'nan'",
        ),
        (
            with_line(5, "2"),
            "bad.w:5: expected the inclined-plane flag (0 or 1) from 0 to 1, found 2",
        ),
        (
            with_line(6, "-3"),
            "bad.w:6: expected the force-field resolution r from 0 to 400, found -3",
        ),
        (
            with_line(7, "0 inf 0"),
            "bad.w:7: expected y of force-field vector 0 of 27000 as a finite number, found 'inf'",
        ),
        (
            valid_text() + "extra\n",
            "bad.w:28031: expected the end of the file after 512 velocities, found 'extra'",
        ),
    ];
    for (text, expected) in cases {
        assert_eq!(error(&text), expected);
    }
    let truncated: String = valid_text()
        .lines()
        .take(27500)
        .collect::<Vec<_>>()
        .join("\n");
    let e = error(&truncated);
    assert!(
        e.starts_with("bad.w:27500: unexpected end of file: expected x of position"),
        "{e}"
    );
    // The course's reader takes any case and any white space.
    let relaxed = valid_text().replacen("RK4\n", "rk4 ", 1);
    assert_eq!(
        parse_world(&relaxed, Path::new("ok.w")).unwrap(),
        world("moveLeft")
    );
}
