//! Keyframed pins (`[body.pin_motion]`, docs/physics.md §1.2): the pinned particles sit at
//! their keyed positions at every step, whatever the integrator, and carry the cloth.

use crate::common::{builtin, root};
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
    spec.bodies[0].pin_motion = Some(MotionSpec { keys: keys() });
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
        let pins: Vec<usize> = scene.spec.bodies[0].pins.clone();
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

fn centroid(scene: &Scene) -> Vec3 {
    let x = &scene.simulation.particles().x;
    x.iter().sum::<Vec3>() / x.len() as f64
}

/// Keys without pins, and keys out of order, are refused with their keys.
#[test]
fn pin_motions_without_pins_or_in_the_wrong_order_are_refused() {
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    spec.bodies[0].pin_motion = Some(MotionSpec { keys: keys() });
    spec.bodies[0].pins.clear();
    let e = spec
        .build(&root().join("assets/scenes"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("pin_motion") && e.contains("`pins`"), "{e}");
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    let mut keys = keys();
    keys.swap(0, 2);
    spec.bodies[0].pin_motion = Some(MotionSpec { keys });
    let e = spec
        .build(&root().join("assets/scenes"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("pin_motion.keys") && e.contains("times must increase"),
        "{e}"
    );
}
