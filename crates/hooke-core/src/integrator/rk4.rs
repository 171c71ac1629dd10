//! Classic fourth-order Runge–Kutta: `s' = s + dt/6 (k1 + 2 k2 + 2 k3 + k4)`.
//!
//! Each stage is one pass over the particles after its scatter: as a block's accelerations
//! are summed, the same pass writes the next stage's trial state for that block, and the
//! last stage writes the new state and checks it. A stage's trial state is complete before
//! the next stage's scatter reads it, and every value is computed by the same operations
//! in the same order as a stage-by-stage loop would, so the fusion changes no bit.

use super::{StepReport, Workspace};
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, SANE_BOUND, Vec3};

/// `|1 + z + z²/2 + z³/6 + z⁴/24| ≤ 1` on the imaginary axis up to `|z| = 2√2`.
pub(super) const STABILITY_RADIUS: f64 = 2.0 * std::f64::consts::SQRT_2;

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    let (half, sixth) = (0.5 * dt, dt / 6.0);
    let Particles {
        x,
        v,
        mass,
        inv_mass,
    } = p;
    let masses = (&mass[..], &inv_mass[..]);
    let Workspace {
        assembly,
        air,
        x0,
        kx,
        kv,
        xt,
        vt,
        ..
    } = ws;
    // The velocity of stage 1 is `v` itself; those of stages 2..4 are their trial
    // velocities, kept in `kx[1..]`. Trial positions alternate between `xt` and `vt`,
    // which this scheme has no other use for.
    let [_, kx1, kx2, kx3] = kx;
    let [kv0, kv1, kv2, kv3] = kv;
    let (xa, xb) = (&mut xt[..], &mut vt[..]);
    let start = (&x[..], &v[..]);
    assembly.accelerations_then(
        model,
        masses,
        start,
        air.evaluate(model.air.as_ref(), &model.aero, start.0, start.1, t),
        kv0,
        (xa, kx1),
        trial(start, start.1, half),
    );
    assembly.accelerations_then(
        model,
        masses,
        (xa, kx1),
        air.evaluate(model.air.as_ref(), &model.aero, xa, kx1, t + half),
        kv1,
        (xb, kx2),
        trial(start, kx1, half),
    );
    assembly.accelerations_then(
        model,
        masses,
        (xb, kx2),
        air.evaluate(model.air.as_ref(), &model.aero, xb, kx2, t + half),
        kv2,
        (xa, kx3),
        trial(start, kx2, dt),
    );
    // The new state goes to `x0` and `vt` (whose trial positions, the third stage's, are
    // spent), which then trade places with the particles' arrays: the old positions become
    // the start positions at no cost.
    let (kx1, kx2, kx3, kv0, kv1, kv2) = (&*kx1, &*kx2, &*kx3, &*kv0, &*kv1, &*kv2);
    let (x, v) = (&*x, &*v);
    let sane = assembly.accelerations_then(
        model,
        masses,
        (xa, kx3),
        air.evaluate(model.air.as_ref(), &model.aero, xa, kx3, t + dt),
        kv3,
        (x0, xb),
        |start, a, xn, vn| {
            for k in 0..a.len() {
                let i = start + k;
                xn[k] = x[i] + (v[i] + kx1[i] * 2.0 + kx2[i] * 2.0 + kx3[i]) * sixth;
                vn[k] = v[i] + (kv0[i] + kv1[i] * 2.0 + kv2[i] * 2.0 + a[k]) * sixth;
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

/// The pass after a stage at trial velocity `vs` (stages 1 to 3), given its accelerations
/// `a`: writes the next stage's trial state `(x + c vs, v + c a)` to `(xn, vn)`.
fn trial<'a>(
    (x, v): (&'a [Vec3], &'a [Vec3]),
    vs: &'a [Vec3],
    c: f64,
) -> impl Fn(usize, &[Vec3], &mut [Vec3], &mut [Vec3]) -> bool + Sync + Send + 'a {
    move |start, a, xn, vn| {
        for j in 0..a.len() {
            let i = start + j;
            xn[j] = x[i] + vs[i] * c;
            vn[j] = v[i] + a[j] * c;
        }
        true
    }
}
