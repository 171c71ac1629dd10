//! Classic fourth-order Runge–Kutta: `s' = s + dt/6 (k1 + 2 k2 + 2 k3 + k4)`.

use super::{StepReport, Workspace, accelerations, for_blocks, trial};
use crate::model::Model;
use crate::particles::Particles;

/// `|1 + z + z²/2 + z³/6 + z⁴/24| ≤ 1` on the imaginary axis up to `|z| = 2√2`.
pub(super) const STABILITY_RADIUS: f64 = 2.0 * std::f64::consts::SQRT_2;

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    let half = 0.5 * dt;
    ws.x0.copy_from_slice(&p.x);
    // Stage 1 at the current state; its position derivative is the velocity itself.
    ws.kx[0].copy_from_slice(&p.v);
    let parts = (&mut ws.assembly, &mut ws.air);
    accelerations(model, parts, p, (&p.x, &p.v), t, &mut ws.kv[0]);
    // Stages 2..4 at s + c·dt·k_{stage-1}, with c = 1/2, 1/2, 1.
    for (stage, c) in [(1, half), (2, half), (3, dt)] {
        trial(
            (&p.x, &p.v),
            (&ws.kx[stage - 1], &ws.kv[stage - 1]),
            c,
            &mut ws.xt,
            &mut ws.vt,
        );
        ws.kx[stage].copy_from_slice(&ws.vt);
        let parts = (&mut ws.assembly, &mut ws.air);
        accelerations(model, parts, p, (&ws.xt, &ws.vt), t + c, &mut ws.kv[stage]);
    }
    let sixth = dt / 6.0;
    let [k1x, k2x, k3x, k4x] = &ws.kx;
    let [k1v, k2v, k3v, k4v] = &ws.kv;
    for_blocks(&mut p.x, &mut p.v, |start, x, v| {
        for k in 0..x.len() {
            let i = start + k;
            x[k] += (k1x[i] + k2x[i] * 2.0 + k3x[i] * 2.0 + k4x[i]) * sixth;
            v[k] += (k1v[i] + k2v[i] * 2.0 + k3v[i] * 2.0 + k4v[i]) * sixth;
        }
    });
    StepReport::SAVED
}
