//! Block descent's step when a collider moves (docs/physics.md §4.1, "A moving collider").
//!
//! Block descent holds every collider at its pose at the end of the step while it iterates,
//! and its bounds keep each particle outside that pose. So it must start outside it too:
//! the collider may jump from one pose to the next only while every point of it moves less
//! than the particles' and surfaces' gap to it. A step in which a collider would close
//! more than [`SHARE`] of that gap is taken in parts, each an implicit-Euler step of its
//! own length in which the collider closes at most that share; the gap is measured anew
//! before each part.

use super::Simulation;
use super::summary;
use crate::integrator::{StepReport, collider_gap};

/// Parts at most in one step: a particle held between a moving collider and something
/// still (or a pinned one in its way) closes its gap to nothing, and the parts stop here.
pub(crate) const MOST_PARTS: u32 = 64;
/// Share of its least gap a collider may close in one part.
pub(crate) const SHARE: f64 = 0.5;

impl Simulation {
    /// One step of block descent from `time`, in as many parts as the moving colliders
    /// need; the solver's counts are the parts' sums.
    pub(super) fn step_swept(&mut self, time: f64) -> StepReport {
        let end = time + self.dt;
        let least = self.dt / f64::from(MOST_PARTS);
        let (mut iterations, mut detections, mut capped, mut residual) = (0, 0, false, 0.0_f64);
        let mut t = time;
        loop {
            let span = self.part((t, end), least).max(least);
            let next = if t + span >= end - 1e-9 * least {
                end
            } else {
                t + span
            };
            for slot in &mut self.model.colliders {
                slot.shape.advance_to(t, next);
            }
            self.start_pins(t, next - t);
            let report = self.integrator.step(
                &self.model,
                &mut self.particles,
                &mut self.workspace,
                (t, next - t),
                &self.contacts.held,
            );
            let vbd = &self.workspace.vbd;
            iterations += vbd.iterations;
            detections += vbd.detections;
            capped |= vbd.capped;
            residual = residual.max(vbd.residual);
            if next == end {
                let vbd = &mut self.workspace.vbd;
                (vbd.iterations, vbd.detections, vbd.capped, vbd.residual) =
                    (iterations, detections, capped, residual);
                return report;
            }
            self.end_pins(next);
            t = next;
        }
    }

    /// The longest span from `t` (at most to `end`) over which no moving collider closes
    /// more than [`SHARE`] of its gap, the colliders being at their pose at `t`; halving
    /// stops at `least`.
    fn part(&self, (t, end): (f64, f64), least: f64) -> f64 {
        let mut span = end - t;
        let (lo, hi) = summary::bounds(&self.particles.x);
        // Gaps beyond this need not be known: the particles' box and a metre.
        let far = (hi - lo).norm() + 1.0;
        for (k, slot) in self.model.colliders.iter().enumerate() {
            let full = slot.shape.sweep((t, end), &lo, &hi);
            if full == 0.0 {
                continue;
            }
            let reach = (full / SHARE).min(far);
            let room = SHARE * collider_gap(&self.model, &self.particles, k, reach);
            // The sweep grows with the span; halve from the proportional guess until it fits.
            let mut s = if full.is_finite() {
                (end - t) * (room / full).min(1.0)
            } else {
                end - t
            };
            while s > least && slot.shape.sweep((t, t + s), &lo, &hi) > room {
                s *= 0.5;
            }
            span = span.min(s);
        }
        span
    }
}
