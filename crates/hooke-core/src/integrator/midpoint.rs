//! Explicit midpoint (RK2): `k1 = f(s)`, `s' = s + dt f(s + dt/2 k1)`.

use super::{StepReport, Workspace, accelerations, for_blocks, trial};
use crate::model::Model;
use crate::particles::Particles;

/// Explicit midpoint amplifies undamped oscillations slightly (by `1 + (ω dt)⁴/4`) and relies
/// on damping; `ω dt = 2` is the bound it reports, as for explicit Euler.
pub(super) const STABILITY_RADIUS: f64 = 2.0;

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    ws.x0.copy_from_slice(&p.x);
    let [k1v, k2v, ..] = &mut ws.kv;
    let parts = (&mut ws.assembly, &mut ws.air);
    accelerations(model, parts, p, (&p.x, &p.v), t, k1v);
    trial((&p.x, &p.v), (&p.v, k1v), 0.5 * dt, &mut ws.xt, &mut ws.vt);
    let parts = (&mut ws.assembly, &mut ws.air);
    accelerations(model, parts, p, (&ws.xt, &ws.vt), t + 0.5 * dt, k2v);
    let vt = &ws.vt;
    for_blocks(&mut p.x, &mut p.v, |start, x, v| {
        for k in 0..x.len() {
            x[k] += vt[start + k] * dt;
            v[k] += k2v[start + k] * dt;
        }
    });
    StepReport::SAVED
}
