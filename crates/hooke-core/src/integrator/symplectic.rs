//! Semi-implicit (symplectic) Euler: `v' = v + dt a(x, v)`, then `x' = x + dt v'`.
//!
//! The spring forces, their sums, the update and the divergence check are one pass over the
//! partitions and particles ([`crate::assembly::Assembly`]'s `scatter_and_finish`): the method that
//! benchmarks run streams each array about once per step. The state is updated in place;
//! the start positions are copied aside as it goes only for a model with a contact phase.

use super::{StepReport, Workspace};
use crate::assembly::kernel::Advance;
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
    // The contact phase needs the start positions to the bit. The divergence report
    // recovers them as `x - v dt` otherwise: copying them every step would cost a fifth of
    // a cloth-1024 step (14.2 against 11.4 ms on two threads).
    let save = model.has_contact_phase();
    let sane = if model.gravity_only() {
        update::<true>(model, p, (t, dt), ws, save)
    } else {
        update::<false>(model, p, (t, dt), ws, save)
    };
    StepReport {
        saved_start: save,
        verdict: Some(sane),
    }
}

/// The step; with `GRAVITY_ONLY` (see [`Model::gravity_only`]) the external force is
/// `m g`, without the general per-particle tests. The state is updated in place, and with
/// `save` each stretch's positions are copied to the workspace's start positions first.
/// Returns whether the state it wrote is sane.
fn update<const GRAVITY_ONLY: bool>(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
    save: bool,
) -> bool {
    let air = ws
        .air
        .evaluate(model.air.as_ref(), &model.aero, &p.x, &p.v, t);
    let (mass, inv_mass) = (&p.mass[..], &p.inv_mass[..]);
    let kernel = ws.assembly.kernel();
    let finish = |start: usize, springs: &[Vec3], x: &mut [Vec3], v: &mut [Vec3]| {
        let n = springs.len().min(x.len()).min(v.len());
        let (mass, inv_mass) = (&mass[start..start + n], &inv_mass[start..start + n]);
        if GRAVITY_ONLY {
            let advance = Advance {
                mass,
                inv_mass,
                gravity: model.gravity,
                dt,
                bound: SANE_BOUND,
            };
            return kernel.advance(&advance, &springs[..n], x, v);
        }
        for k in 0..n {
            // A pinned particle keeps its state.
            if inv_mass[k] == 0.0 {
                continue;
            }
            let (xk, vk) = (x[k], v[k]);
            // Without air nothing is added, so vacuum runs keep every bit.
            let pairwise = if air.is_empty() {
                springs[k]
            } else {
                springs[k] + air[start + k]
            };
            let f = model.total_force(start + k, mass[k], &xk, &vk, pairwise);
            v[k] = vk + f * inv_mass[k] * dt;
            x[k] = xk + v[k] * dt;
        }
        parallel::sane(&x[..n], &v[..n], SANE_BOUND)
    };
    let saved = if save { &mut ws.x0[..] } else { &mut [][..] };
    ws.assembly
        .scatter_and_finish((&mut p.x, &mut p.v), saved, finish)
}
