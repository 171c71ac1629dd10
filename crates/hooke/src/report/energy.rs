//! Total energy over time for each built-in scene and integrator, beside what the damping
//! predicts: the power springs' damping and drag take out, `Σ kd (Δv·u)² + drag Σ |v|²`,
//! integrated step by step. Where nothing else acts (no collider, air, field or grab) the
//! energy lost must be what the damping took, up to the scheme's own error.

use crate::Result;
use hooke_core::{Integrator, Summary};
use hooke_scene::{Overrides, Scene};
use serde::Serialize;

/// One scene and integrator over the window.
#[derive(Serialize)]
pub(crate) struct EnergyRun {
    pub(crate) scene: String,
    pub(crate) integrator: String,
    pub(crate) dt: f64,
    /// `(t, E)` at each sample, J; stops early at a divergence.
    pub(crate) energy: Vec<(f64, f64)>,
    /// `(t, E(0) − ∫ P dt)`: the energy the damping alone would leave.
    pub(crate) predicted: Vec<(f64, f64)>,
    pub(crate) diverged: bool,
    /// Whether damping is all that takes energy out (no collider, air, field).
    pub(crate) closed: bool,
    /// `E(end) − E(0)` and `−∫ P dt`, J.
    pub(crate) change: f64,
    pub(crate) predicted_change: f64,
}

/// The damping's power now, W.
fn damping_power(scene: &Scene) -> f64 {
    let sim = &scene.simulation;
    let (model, p) = (sim.model(), sim.particles());
    let springs: f64 = model
        .springs
        .iter()
        .map(|s| {
            let d = p.x[s.j as usize] - p.x[s.i as usize];
            let len = d.norm();
            if len == 0.0 {
                return 0.0;
            }
            let dv = p.v[s.j as usize] - p.v[s.i as usize];
            let along = dv.dot(&d) / len;
            s.kd * along * along
        })
        .sum();
    let drag: f64 = (0..p.len())
        .filter(|&i| p.inv_mass[i] != 0.0)
        .map(|i| model.drag_on(p.mass[i]) * p.v[i].norm_squared())
        .sum();
    springs + drag
}

/// Faster than sound, or ten times more energy than the run started with: the scheme is
/// blowing up, though no particle has yet left the world.
fn blown_up(scene: &Scene, e0: f64, e: f64) -> bool {
    let fastest = scene
        .simulation
        .particles()
        .v
        .iter()
        .fold(0.0f64, |m, v| m.max(v.norm()));
    !e.is_finite() || fastest > 343.0 || (e - e0).abs() > 10.0 * e0.abs().max(0.1)
}

fn energy(scene: &Scene) -> f64 {
    let s = Summary::of(scene.simulation.model(), scene.simulation.particles());
    s.kinetic + s.potential
}

/// Runs built-in `name` with `integrator` for `window` seconds at the scene's step.
fn run(name: &str, integrator: Integrator, window: f64) -> Result<EnergyRun> {
    let overrides = Overrides {
        integrator: Some(integrator),
        // The large-step integrators at the step they are for, not the explicit one's.
        dt: integrator
            .stability_radius()
            .is_infinite()
            .then_some(LARGE_STEP),
        ..Overrides::default()
    };
    let mut scene = crate::source::build(name, &overrides)?;
    let dt = scene.simulation.dt();
    let model = scene.simulation.model();
    let closed = model.colliders.is_empty() && model.air.is_none() && model.field.is_none();
    let steps = (window / dt).round().max(1.0) as u64;
    let every = (steps / 120).max(1);
    let e0 = energy(&scene);
    let (mut lost, mut power) = (0.0, damping_power(&scene));
    let mut out = EnergyRun {
        scene: name.to_string(),
        integrator: integrator.to_string(),
        dt,
        energy: vec![(0.0, e0)],
        predicted: vec![(0.0, e0)],
        diverged: false,
        closed,
        change: 0.0,
        predicted_change: 0.0,
    };
    for n in 1..=steps {
        crate::interrupt::check(&scene.simulation)?;
        if scene.simulation.step().is_err() {
            out.diverged = true;
            break;
        }
        let next = damping_power(&scene);
        lost += 0.5 * (power + next) * dt;
        power = next;
        if n % every == 0 || n == steps {
            let t = n as f64 * dt;
            let e = energy(&scene);
            out.energy.push((t, e));
            out.predicted.push((t, e0 - lost));
            if blown_up(&scene, e0, e) {
                // An exploding cloth makes every later step slower (its contacts spread
                // over the world); the run has said what it had to.
                out.diverged = true;
                break;
            }
        }
    }
    out.change = out.energy.last().map_or(0.0, |e| e.1) - e0;
    out.predicted_change = -lost;
    Ok(out)
}

/// The step of the large-step integrators' runs: a display frame at 60 Hz, s.
pub(crate) const LARGE_STEP: f64 = 1.0 / 60.0;

/// The seconds of each run: enough to see drift and damping, short enough for the report.
pub(crate) fn window(quick: bool) -> f64 {
    if quick { 0.05 } else { 0.5 }
}

/// Every built-in scene with every integrator that takes it (block descent refuses moving
/// colliders, docs/physics.md §2.1); `tick` after each scene.
pub(crate) fn runs(quick: bool, tick: &mut dyn FnMut()) -> Result<Vec<EnergyRun>> {
    let mut out = Vec::new();
    for (name, make) in hooke_scene::builtin::BUILTINS {
        let moving = make().colliders.iter().any(|c| c.motion.is_some());
        for integrator in Integrator::ALL {
            if moving && integrator.solves_contacts() {
                continue;
            }
            out.push(run(name, integrator, window(quick))?);
        }
        tick();
    }
    Ok(out)
}
