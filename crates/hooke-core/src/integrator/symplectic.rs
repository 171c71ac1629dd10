//! Semi-implicit (symplectic) Euler: `v' = v + dt a(x, v)`, then `x' = x + dt v'`.

use super::{Workspace, accelerations};
use crate::model::Model;
use crate::particles::Particles;

pub(super) fn step(model: &Model, p: &mut Particles, dt: f64, ws: &mut Workspace) {
    ws.x0.copy_from_slice(&p.x);
    let a = &mut ws.kv[0];
    accelerations(model, &ws.adjacency, p, &p.x, &p.v, &mut ws.spring_force, a);
    for ((x, v), a) in p.x.iter_mut().zip(p.v.iter_mut()).zip(a.iter()) {
        *v += a * dt;
        *x += *v * dt;
    }
}
