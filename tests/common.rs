//! Helpers shared by the suite.

use hooke_scene::{Overrides, Scene, SceneSpec};
use std::path::{Path, PathBuf};

/// The workspace root, found from this crate's manifest, never the working directory.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// `spec` switched to `integrator`.
pub fn with_integrator(mut spec: SceneSpec, integrator: hooke_core::Integrator) -> SceneSpec {
    Overrides {
        integrator: Some(integrator),
        ..Overrides::default()
    }
    .apply(&mut spec)
    .unwrap();
    spec
}

/// A built-in scene, with overrides, built.
pub fn builtin(name: &str, overrides: &Overrides) -> Scene {
    let mut spec: SceneSpec = hooke_scene::builtin::builtin(name).unwrap();
    overrides.apply(&mut spec).unwrap();
    spec.build(&root().join("assets/scenes")).unwrap()
}

/// The height of the lowest particle of `scene`, metres.
pub fn lowest(scene: &Scene) -> f64 {
    let x = &scene.simulation.particles().x;
    x.iter().map(|p| p.y).fold(f64::INFINITY, f64::min)
}

/// Magnitudes below this (a nanometre, a nanojoule, a nanometre per second) are round-off
/// left by cancellation, such as the z of a particle on a plane of symmetry, not physics.
pub const NOISE_FLOOR: f64 = 1e-9;

/// Rounds to `digits` significant digits, for snapshots that must not depend on the last bits
/// of libm's trigonometry or of the order forces are summed in; values below [`NOISE_FLOOR`]
/// become 0.
pub fn round_sig(x: f64, digits: i32) -> f64 {
    if x.abs() < NOISE_FLOOR {
        return 0.0;
    }
    if !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}
