//! Explicit Euler: `x' = x + dt v`, `v' = v + dt a(x, v)`, both from the old state.
//!
//! One pass over the particles after the scatter writes the new state beside the old one
//! (other threads may still read the old state for their springs) and checks it; the new
//! arrays then trade places with the particles', so the old positions become the start
//! positions at no cost.

use super::{StepReport, Workspace};
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, SANE_BOUND};

/// Explicit Euler amplifies every undamped oscillation at any step and relies on damping;
/// beyond `ω dt = 2` no damping can help, so that is the bound it reports.
pub(super) const STABILITY_RADIUS: f64 = 2.0;

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    let (x, v) = (&p.x[..], &p.v[..]);
    let sane = ws.assembly.accelerations_then(
        model,
        (&p.mass, &p.inv_mass),
        (x, v),
        ws.air.evaluate(model.air.as_ref(), &model.aero, x, v, t),
        &mut ws.kv[0],
        (&mut ws.x0, &mut ws.vt),
        |start, a, xn, vn| {
            for k in 0..a.len() {
                let i = start + k;
                xn[k] = x[i] + v[i] * dt;
                vn[k] = v[i] + a[k] * dt;
            }
            parallel::sane(xn, vn, SANE_BOUND)
        },
    );
    std::mem::swap(&mut p.x, &mut ws.x0);
    std::mem::swap(&mut p.v, &mut ws.vt);
    StepReport {
        saved_start: true,
        verdict: Some(sane),
    }
}
