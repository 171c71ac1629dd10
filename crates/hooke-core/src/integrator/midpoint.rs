//! Explicit midpoint (RK2): `k1 = f(s)`, `s' = s + dt f(s + dt/2 k1)`.

use super::{Workspace, accelerations};
use crate::model::Model;
use crate::particles::Particles;

#[allow(
    clippy::needless_range_loop,
    reason = "six arrays advance in lockstep; one index reads clearest"
)]
pub(super) fn step(model: &Model, p: &mut Particles, dt: f64, ws: &mut Workspace) {
    let half = 0.5 * dt;
    ws.x0.copy_from_slice(&p.x);
    let [k1v, k2v, ..] = &mut ws.kv;
    accelerations(
        model,
        &ws.adjacency,
        p,
        &p.x,
        &p.v,
        &mut ws.spring_force,
        k1v,
    );
    for i in 0..p.len() {
        ws.xt[i] = p.x[i] + p.v[i] * half;
        ws.vt[i] = p.v[i] + k1v[i] * half;
    }
    accelerations(
        model,
        &ws.adjacency,
        p,
        &ws.xt,
        &ws.vt,
        &mut ws.spring_force,
        k2v,
    );
    for i in 0..p.len() {
        p.x[i] += ws.vt[i] * dt;
        p.v[i] += k2v[i] * dt;
    }
}
