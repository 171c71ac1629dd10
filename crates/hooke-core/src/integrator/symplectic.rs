//! Semi-implicit (symplectic) Euler: `v' = v + dt a(x, v)`, then `x' = x + dt v'`.
//!
//! The spring forces, their sums, the update and the divergence check are one pass over the
//! partitions and particles ([`crate::Assembly`]'s `scatter_and_finish`): the method that
//! benchmarks run streams each array about once per step. The new state is written beside
//! the old one, whose positions then serve as the start positions.

use super::{StepReport, Workspace};
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, SANE_BOUND, Vec3};

/// Symplectic Euler keeps an undamped oscillation bounded while `ω dt < 2`.
pub(super) const STABILITY_RADIUS: f64 = 2.0;

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    let sane = if model.gravity_only() {
        update::<true>(model, p, (t, dt), ws)
    } else {
        update::<false>(model, p, (t, dt), ws)
    };
    StepReport {
        saved_start: true,
        verdict: Some(sane),
    }
}

/// The step; with `GRAVITY_ONLY` (see [`Model::gravity_only`]) the external force is
/// `m g`, without the general per-particle tests. The new state goes to the workspace's
/// spare arrays, which then trade places with the particles' (so the old positions become
/// the start positions, at no cost). Returns whether the state it wrote is sane.
fn update<const GRAVITY_ONLY: bool>(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> bool {
    let air = ws.air.evaluate(model, &p.x, &p.v, t);
    let (x, v) = (&p.x[..], &p.v[..]);
    let (mass, inv_mass) = (&p.mass[..], &p.inv_mass[..]);
    let finish = |start: usize, springs: &[Vec3], xn: &mut [Vec3], vn: &mut [Vec3]| {
        let n = springs.len().min(xn.len()).min(vn.len());
        let (x, v) = (&x[start..start + n], &v[start..start + n]);
        let (mass, inv_mass) = (&mass[start..start + n], &inv_mass[start..start + n]);
        for k in 0..n {
            if inv_mass[k] == 0.0 {
                (xn[k], vn[k]) = (x[k], v[k]);
                continue;
            }
            let f = if GRAVITY_ONLY {
                model.gravity * mass[k] + springs[k]
            } else {
                // Without air nothing is added, so vacuum runs keep every bit.
                let pairwise = if air.is_empty() {
                    springs[k]
                } else {
                    springs[k] + air[start + k]
                };
                model.total_force(start + k, mass[k], &x[k], &v[k], pairwise)
            };
            vn[k] = v[k] + f * inv_mass[k] * dt;
            xn[k] = x[k] + vn[k] * dt;
        }
        parallel::sane(&xn[..n], &vn[..n], SANE_BOUND)
    };
    let sane = ws
        .assembly
        .scatter_and_finish((x, v), (&mut ws.xt, &mut ws.vt), finish);
    std::mem::swap(&mut p.x, &mut ws.xt);
    std::mem::swap(&mut ws.xt, &mut ws.x0);
    std::mem::swap(&mut p.v, &mut ws.vt);
    sane
}
