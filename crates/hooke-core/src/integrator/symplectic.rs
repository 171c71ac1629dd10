//! Semi-implicit (symplectic) Euler: `v' = v + dt a(x, v)`, then `x' = x + dt v'`.
//!
//! The force gather, the update, saving the start positions and the divergence check are
//! one pass over the particles: the method that benchmarks run streams each array once per
//! step. The start positions are saved only for models with a contact phase, the one
//! reader that needs them exactly (see [`StepReport::saved_start`]).

use super::{StepReport, Workspace};
use crate::assembly::{BLOCK, REDUCE_BLOCK};
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
    let save = model.has_contact_phase();
    let sane = match (model.gravity_only(), save) {
        (true, true) => update::<true, true>(model, p, (t, dt), ws),
        (true, false) => update::<true, false>(model, p, (t, dt), ws),
        (false, true) => update::<false, true>(model, p, (t, dt), ws),
        (false, false) => update::<false, false>(model, p, (t, dt), ws),
    };
    StepReport {
        saved_start: save,
        verdict: Some(sane),
    }
}

/// The step; with `GRAVITY_ONLY` (see [`Model::gravity_only`]) the external force is
/// `m g`, without the general per-particle tests; with `SAVE_START` the start positions
/// go to `x0`. Returns whether the state it wrote is sane.
fn update<const GRAVITY_ONLY: bool, const SAVE_START: bool>(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> bool {
    let air = ws.air.evaluate(model, &p.x, &p.v, t);
    ws.assembly.scatter(&p.x, &p.v);
    let asm = &ws.assembly;
    let (mass, inv_mass) = (&p.mass, &p.inv_mass);
    parallel::all_blocks3(BLOCK, &mut p.x, &mut p.v, &mut ws.x0, |start, x, v, x0| {
        let mut springs = [Vec3::zeros(); REDUCE_BLOCK];
        let mut sane = true;
        let chunks = x.chunks_mut(REDUCE_BLOCK).zip(v.chunks_mut(REDUCE_BLOCK));
        for (c, ((x, v), x0)) in chunks.zip(x0.chunks_mut(REDUCE_BLOCK)).enumerate() {
            let start = start + c * REDUCE_BLOCK;
            let n = x.len().min(v.len()).min(x0.len());
            let springs = &mut springs[..n];
            asm.gather_block(start, springs);
            let (mass, inv_mass) = (&mass[start..start + n], &inv_mass[start..start + n]);
            for k in 0..n {
                if SAVE_START {
                    x0[k] = x[k];
                }
                if inv_mass[k] == 0.0 {
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
                v[k] += f * inv_mass[k] * dt;
                x[k] += v[k] * dt;
            }
            sane &= parallel::sane(x, v, SANE_BOUND);
        }
        sane
    })
}
