//! The cloth-N benchmark workload (`docs/benchmarks.md`), as a scene.

use crate::spec::*;
use hooke_core::Integrator;

/// Steps the workload measures.
pub const WORKLOAD_STEPS: u64 = 200;

/// `n × n` particles on the unit square in the x-z plane at `y = 1`, particle `i n + j` at
/// `(i h, 1, j h)` with `h = 1/(n-1)`; structural, shear and bend springs with `ks = 1000`,
/// `kd = 0.01`; 1 kg spread equally; particles `(0,0)` and `(0,n-1)` pinned; symplectic
/// Euler with `dt = 1e-5` for [`WORKLOAD_STEPS`] steps; gravity only.
///
/// ```
/// let spec = hooke_scene::workload::cloth(64);
/// let scene = spec.build(std::path::Path::new(".")).unwrap();
/// let n = 64;
/// assert_eq!(scene.simulation.model().springs.len(), 2 * n * (n - 1) + 2 * (n - 1) * (n - 1) + 2 * n * (n - 2));
/// ```
pub fn cloth(n: usize) -> SceneSpec {
    let params = || {
        Some(SpringParams {
            ks: NonNegative::of(1000.0),
            kd: NonNegative::of(0.01),
        })
    };
    let zero = [Finite::of(0.0); 3];
    SceneSpec {
        name: format!("cloth-{n}"),
        description: format!("the cloth-N benchmark workload at N = {n}"),
        simulation: SimulationSpec {
            integrator: IntegratorName(Integrator::Symplectic),
            dt: Positive::of(1e-5),
            duration: None,
            steps: Some(WORKLOAD_STEPS),
            every: WORKLOAD_STEPS,
            gravity: [Finite::of(0.0), Finite::of(-9.81), Finite::of(0.0)],
            drag: NonNegative::of(0.0),
            mass_drag: NonNegative::of(0.0),
            tolerance: None,
            iterations: None,
            air: None,
        },
        bodies: vec![BodySpec {
            name: "cloth".into(),
            mass: Some(Positive::of(1.0 / (n * n) as f64)),
            origin: [Finite::of(0.0), Finite::of(1.0), Finite::of(0.0)],
            rotate: zero,
            velocity: zero,
            pins: vec![0, n - 1].into(),
            positions: None,
            velocities: None,
            shape: ShapeSpec::Grid {
                size: [n, n],
                spacing: Positive::of(1.0 / (n - 1) as f64),
            },
            springs: SpringsSpec {
                structural: params(),
                shear: params(),
                bend: params(),
                pairs: Vec::new(),
            },
            // The workload measures springs alone: no contact phase.
            material: None,
            pin_motion: None,
            thickness: Some(NonNegative::of(0.0)),
            self_collision: None,
            friction: None,
            aero: None,
        }],
        colliders: Vec::new(),
        force_field: None,
    }
}

/// The index of the workload's centre particle `(n/2, n/2)`.
pub fn centre(n: usize) -> usize {
    (n / 2) * n + n / 2
}
