//! Explicit midpoint (RK2): `k1 = f(s)`, `s' = s + dt f(s + dt/2 k1)`.
//!
//! Each stage is one pass over the particles after its scatter, as in [`super::rk4`]: the
//! first writes the midpoint state, the second the new state beside the old one, which
//! then trade places (the old positions become the start positions at no cost).

use super::{StepReport, Workspace};
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, SANE_BOUND};

/// Explicit midpoint amplifies undamped oscillations slightly (by `1 + (ω dt)⁴/4`) and relies
/// on damping; `ω dt = 2` is the bound it reports, as for explicit Euler.
pub(super) const STABILITY_RADIUS: f64 = 2.0;

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    let half = 0.5 * dt;
    let (x, v) = (&p.x[..], &p.v[..]);
    let masses = (&p.mass[..], &p.inv_mass[..]);
    let [k1v, k2v, ..] = &mut ws.kv;
    let (xt, vt) = (&mut ws.xt[..], &mut ws.vt[..]);
    ws.assembly.accelerations_then(
        model,
        masses,
        (x, v),
        ws.air.evaluate(model.air.as_ref(), &model.aero, x, v, t),
        k1v,
        (&mut *xt, &mut *vt),
        |start, a, xt, vt| {
            for k in 0..a.len() {
                let i = start + k;
                xt[k] = x[i] + v[i] * half;
                vt[k] = v[i] + a[k] * half;
            }
            true
        },
    );
    // The new velocities go to `kx[0]`, which this scheme has no other use for.
    let (xt, vt) = (&*xt, &*vt);
    let sane = ws.assembly.accelerations_then(
        model,
        masses,
        (xt, vt),
        ws.air
            .evaluate(model.air.as_ref(), &model.aero, xt, vt, t + half),
        k2v,
        (&mut ws.x0, &mut ws.kx[0]),
        |start, a, xn, vn| {
            for k in 0..a.len() {
                let i = start + k;
                xn[k] = x[i] + vt[i] * dt;
                vn[k] = v[i] + a[k] * dt;
            }
            parallel::sane(xn, vn, SANE_BOUND)
        },
    );
    std::mem::swap(&mut p.x, &mut ws.x0);
    std::mem::swap(&mut p.v, &mut ws.kx[0]);
    StepReport {
        saved_start: true,
        verdict: Some(sane),
    }
}
