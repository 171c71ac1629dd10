//! Explicit Euler: `x' = x + dt v`, `v' = v + dt a(x, v)`, both from the old state.

use super::{StepReport, Workspace, accelerations, for_blocks};
use crate::model::Model;
use crate::particles::Particles;

/// Explicit Euler amplifies every undamped oscillation at any step and relies on damping;
/// beyond `ω dt = 2` no damping can help, so that is the bound it reports.
pub(super) const STABILITY_RADIUS: f64 = 2.0;

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    ws.x0.copy_from_slice(&p.x);
    let a = &mut ws.kv[0];
    accelerations(
        model,
        (&mut ws.assembly, &mut ws.air),
        p,
        (&p.x, &p.v),
        t,
        a,
    );
    for_blocks(&mut p.x, &mut p.v, |start, x, v| {
        for k in 0..x.len() {
            x[k] += v[k] * dt;
            v[k] += a[start + k] * dt;
        }
    });
    StepReport::SAVED
}
