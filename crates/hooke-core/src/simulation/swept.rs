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
use crate::particles::Vec3;

/// The shortest part is the step over this: a particle held between a moving collider and
/// something still (or a pinned one in its way) closes its gap to nothing, and the parts
/// stop shrinking here. A ball keyed at 1000 m/s through a hanging cloth at 1/60 s takes
/// about 200 parts in the step it passes, each far longer than this.
pub const MOST_PARTS: u32 = 1 << 16;
/// Parts at most in one step: past them the rest of the step is one part (and the crossing
/// watch says so if a surface ends through the collider).
pub(crate) const PART_BUDGET: u32 = 4096;
/// Share of its least gap a collider may close in one part.
pub(crate) const SHARE: f64 = 0.5;
/// How far, in the surface's thickness, a keyed pin may move in one part apart from the
/// mean motion of the surfaces' free particles. Block descent's bounds keep the free
/// particles near a pin from closing on it by what it moves apart (docs/physics.md §4.1),
/// so a pin that jumps far ahead of its cloth (keyed to 30 m/s from rest) drags it through
/// parts instead of freezing the particles around it.
pub(crate) const PIN_ROOM: f64 = 2.0;

impl Simulation {
    /// One step of block descent from `time`, in as many parts as the moving colliders
    /// need; the solver's counts are the parts' sums.
    pub(super) fn step_swept(&mut self, time: f64) -> StepReport {
        let end = time + self.dt;
        let least = self.dt / f64::from(MOST_PARTS);
        let (mut iterations, mut detections, mut capped, mut residual) = (0, 0, false, 0.0_f64);
        let mut t = time;
        let mut parts = 0;
        loop {
            parts += 1;
            let span = if parts < PART_BUDGET {
                // The rest of the step in equal parts no longer than the collider allows, so
                // that no sliver of a part is left at its end.
                let most = self.part((t, end), least).max(least);
                (end - t) / ((end - t) / most).ceil().max(1.0)
            } else {
                end - t
            };
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
                (
                    vbd.iterations,
                    vbd.detections,
                    vbd.capped,
                    vbd.residual,
                    vbd.step_parts,
                ) = (iterations, detections, capped, residual, parts);
                return report;
            }
            self.end_pins(next);
            t = next;
        }
    }

    /// The longest span from `t` (at most to `end`) over which no moving collider closes
    /// more than [`SHARE`] of its gap, the colliders being at their pose at `t`, and no
    /// keyed pin of a surface moves more than [`PIN_ROOM`] thicknesses apart from the
    /// surfaces' mean motion; halving stops at `least`.
    fn part(&self, (t, end): (f64, f64), least: f64) -> f64 {
        let mut span = self.pin_part((t, end), least);
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

    /// The longest span from `t` (at most to `end`, halving down to `least`) over which no
    /// keyed pin of an active surface moves farther than [`PIN_ROOM`] thicknesses from
    /// where the free surface particles' mean velocity would carry it.
    fn pin_part(&self, (t, end): (f64, f64), least: f64) -> f64 {
        let full = end - t;
        let thickness = self
            .model
            .active_surfaces()
            .map(|(_, s)| s.thickness)
            .fold(f64::INFINITY, f64::min);
        if self.model.pin_motions.is_empty() || !thickness.is_finite() {
            return full;
        }
        let p = &self.particles;
        let (mut momentum, mut mass, mut still) = (Vec3::zeros(), 0.0, false);
        for (_, s) in self.model.active_surfaces() {
            for i in s.particles.clone() {
                if !p.is_pinned(i) {
                    momentum += p.v[i] * p.mass[i];
                    mass += p.mass[i];
                } else {
                    still |= p.v[i] == Vec3::zeros();
                }
            }
        }
        // The free particles' shared translation, as block descent's detection takes it:
        // none while a surface particle is pinned where it is.
        let mean = if mass > 0.0 && !still {
            momentum / mass
        } else {
            Vec3::zeros()
        };
        let apart = |s: f64| {
            self.model
                .pin_motions
                .iter()
                .flat_map(|m| m.positions(t).zip(m.positions(t + s)))
                .map(|((_, a), (_, b))| (b - a - mean * s).norm())
                .fold(0.0, f64::max)
        };
        let room = PIN_ROOM * thickness;
        let mut s = full;
        while s > least && apart(s) > room {
            s *= 0.5;
        }
        s
    }
}
