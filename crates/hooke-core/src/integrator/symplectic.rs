//! Semi-implicit (symplectic) Euler: `v' = v + dt a(x, v)`, then `x' = x + dt v'`.
//!
//! The force gather, the update, saving the start positions and the divergence check are
//! one pass over the particles: the method that benchmarks run streams each array once per
//! step.

use super::Workspace;
use crate::assembly::{Assembly, BLOCK, REDUCE_BLOCK};
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, Vec3};
use crate::simulation::SANE_BOUND;

pub(super) fn step(model: &Model, p: &mut Particles, dt: f64, ws: &mut Workspace) {
    ws.assembly.scatter(&p.x, &p.v);
    let asm = &ws.assembly;
    let (mass, inv_mass) = (&p.mass, &p.inv_mass);
    let sane = parallel::all_blocks3(BLOCK, &mut p.x, &mut p.v, &mut ws.x0, |start, x, v, x0| {
        let mut springs = [Vec3::zeros(); REDUCE_BLOCK];
        let mut sane = true;
        let chunks = x.chunks_mut(REDUCE_BLOCK).zip(v.chunks_mut(REDUCE_BLOCK));
        for (c, ((x, v), x0)) in chunks.zip(x0.chunks_mut(REDUCE_BLOCK)).enumerate() {
            let start = start + c * REDUCE_BLOCK;
            let springs = &mut springs[..x.len()];
            asm.gather_block(start, springs);
            for k in 0..x.len() {
                let i = start + k;
                x0[k] = x[k];
                if inv_mass[i] == 0.0 {
                    continue;
                }
                let f = Assembly::force(model, mass[i], &x[k], &v[k], i, springs[k]);
                v[k] += f * inv_mass[i] * dt;
                x[k] += v[k] * dt;
            }
            sane &= parallel::sane(x, v, SANE_BOUND);
        }
        sane
    });
    ws.sane = Some(sane);
}
