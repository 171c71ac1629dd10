//! Forces and equilibria: the spring force of docs/physics.md §1 case by case, and the chain
//! hanging at rest with each spring stretched by the load below it.

use hooke_core::{Spring, SpringKind, Vec3};
use hooke_scene::Overrides;

#[test]
fn spring_forces_pull_stretched_ends_together_and_damp_separation() {
    let s = Spring {
        i: 0,
        j: 1,
        rest: 1.0,
        ks: 10.0,
        kd: 2.0,
        kind: SpringKind::Other,
    };
    let (xi, xj) = (Vec3::new(2.0, 0.0, 0.0), Vec3::zeros());
    let f = s.force(&xi, &xj, &Vec3::zeros(), &Vec3::zeros());
    assert_eq!(
        f,
        Vec3::new(-10.0, 0.0, 0.0),
        "stretched: i pulled towards j"
    );
    let f = s.force(
        &Vec3::new(0.5, 0.0, 0.0),
        &xj,
        &Vec3::zeros(),
        &Vec3::zeros(),
    );
    assert_eq!(f, Vec3::new(5.0, 0.0, 0.0), "compressed: i pushed away");
    let f = s.force(
        &Vec3::new(1.0, 0.0, 0.0),
        &xj,
        &Vec3::new(3.0, 1.0, 0.0),
        &Vec3::zeros(),
    );
    assert_eq!(
        f,
        Vec3::new(-6.0, 0.0, 0.0),
        "separating at 3 m/s: damped along the spring only"
    );
    let f = s.force(&xj, &xj, &Vec3::new(1.0, 0.0, 0.0), &Vec3::zeros());
    assert_eq!(f, Vec3::zeros(), "coincident ends: no force, no NaN");
}

#[test]
fn the_chain_hangs_with_the_static_stretch_of_its_load() {
    // Spring j (1-based from the anchor) carries the N - j + 1 masses below it.
    let mut scene = crate::common::builtin("chain", &Overrides::default());
    scene.simulation.advance(scene.steps).unwrap();
    let p = scene.simulation.particles();
    let n = hooke_scene::builtin::CHAIN_COUNT - 1;
    for j in 1..=n {
        let length = (p.x[j] - p.x[j - 1]).norm();
        let expected = 0.15
            + (n - j + 1) as f64 * hooke_scene::builtin::CHAIN_MASS * 9.81
                / hooke_scene::builtin::CHAIN_KS;
        assert!(
            (length - expected).abs() < 2e-4,
            "spring {j}: length {length}, expected {expected}"
        );
    }
}
