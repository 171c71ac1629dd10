//! A start inside a collider (docs/physics.md §3.4): before the first step, every free
//! particle inside a collider with a velocity-level response (restitution, stick), or
//! nearer its surface than its contact thickness, is moved out along the contact's normal
//! to that thickness, as the contact phase would move it after a step, and its velocity
//! is kept. Penalty colliders push out with their own force, as the course specifies, and
//! are left to it.
//!
//! The move is refused when it would leave a spring through the collider (a cloth started
//! inside a tabletop whose particles would part to its top and its side, or through a ball),
//! tear or crush a spring (half its length or more: a body swallowed by a large solid), or
//! leave a particle still inside one: such a start cannot be put right particle by particle, and a run from it
//! pumps energy into the springs that the contact fights.

use crate::particles::Vec3;
use crate::simulation::Simulation;

/// Particles moved out of one collider at the start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PushedOut {
    /// The collider's index.
    pub collider: usize,
    /// How many particles were moved.
    pub particles: usize,
    /// The longest move, metres.
    pub deepest: f64,
}

/// Why a start could not be pushed out of its colliders.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StartInside {
    /// Moved out, a spring would pass through the collider.
    #[error(
        "particles {0} and {1} start inside collider[{2}] ({3}) or on either side of it, and \
         moved out of it their spring would pass through it: start the body outside the \
         collider, with a gap of at least its contact thickness"
    )]
    Through(usize, usize, usize, String),
    /// Moved out, a spring would be torn or crushed: the collider holds so much of the body
    /// (a cloth through a ball, a body that a large solid swallows) that moving each particle
    /// to its nearest surface point is no shape of the body.
    #[error(
        "particles {0} and {1} start inside collider[{2}] ({3}) or nearer it than their \
         contact thickness, and moved out of it their spring would go from {4} m to {5} m \
         long: the collider holds too much of the body to move it out particle by particle; \
         start the body outside the collider, with a gap of at least its contact thickness"
    )]
    Deformed(usize, usize, usize, String, crate::Approx, crate::Approx),
    /// A particle is still inside a collider after the move (colliders overlapping there).
    #[error(
        "particle {0} starts inside collider[{1}] ({2}) and cannot be moved out of every \
         collider: start the body outside the colliders"
    )]
    Stuck(usize, usize, String),
}

impl Simulation {
    /// Moves the free particles that start inside a velocity-level collider, or nearer
    /// than their contact thickness, out to that thickness (see the module's documentation);
    /// returns what moved, per collider. Refused, the state is left as it was. Only before
    /// the first step: later it does nothing.
    pub fn push_out_start(&mut self) -> Result<Vec<PushedOut>, StartInside> {
        if self.step != 0 {
            return Ok(Vec::new());
        }
        let model = &self.model;
        let p = &mut self.particles;
        let before = p.x.clone();
        let mut out = Vec::new();
        // Per particle: the last collider that moved it.
        let mut moved = vec![None; p.len()];
        for (k, slot) in model.colliders.iter().enumerate() {
            if slot.response.is_force() {
                continue;
            }
            let mut count = 0;
            let mut deepest = 0.0f64;
            for (i, x) in p.x.iter_mut().enumerate() {
                if p.inv_mass[i] == 0.0 {
                    continue;
                }
                let mut shift = Vec3::zeros();
                slot.shape
                    .contacts_within(x, model.margin(i), &mut |c| shift += c.normal * c.depth);
                if shift != Vec3::zeros() {
                    *x += shift;
                    count += 1;
                    deepest = deepest.max(shift.norm());
                    moved[i] = Some(k);
                }
            }
            if count > 0 {
                out.push(PushedOut {
                    collider: k,
                    particles: count,
                    deepest,
                });
            }
        }
        if out.is_empty() {
            return Ok(out);
        }
        if let Err(e) = through_or_stuck(model, (&before, &p.x), &moved) {
            p.x = before;
            return Err(e);
        }
        // The run's energy and its stable-step estimate start from the state it runs from.
        self.watch = super::runaway::EnergyWatch::new(&self.model, &self.particles, self.dt);
        self.initial = self.particles.clone();
        Ok(out)
    }
}

/// Share of a spring's length (or its rest length, the longer) by which moving a start out
/// of a collider may change it: more is a body torn or crushed, not one put beside the
/// collider.
const MOST_CHANGE: f64 = 0.5;

/// The first spring of a moved particle that passes through a collider or changes its length
/// by more than [`MOST_CHANGE`] (`before` → `x`), or moved particle still inside a collider.
fn through_or_stuck(
    model: &crate::model::Model,
    (before, x): (&[Vec3], &[Vec3]),
    moved: &[Option<usize>],
) -> Result<(), StartInside> {
    for s in &model.springs {
        let (i, j) = (s.i as usize, s.j as usize);
        let Some(k) = moved[i].or(moved[j]) else {
            continue;
        };
        let (was, now) = ((before[i] - before[j]).norm(), (x[i] - x[j]).norm());
        if (now - was).abs() > MOST_CHANGE * was.max(s.rest) {
            let name = model.colliders[k].shape.name();
            return Err(StartInside::Deformed(
                i,
                j,
                k,
                name,
                crate::Approx(was),
                crate::Approx(now),
            ));
        }
    }
    for (k, slot) in model.colliders.iter().enumerate() {
        if slot.response.is_force() {
            continue;
        }
        for s in &model.springs {
            let (i, j) = (s.i as usize, s.j as usize);
            if (moved[i].is_some() || moved[j].is_some()) && slot.shape.segment_meets(&x[i], &x[j])
            {
                return Err(StartInside::Through(i, j, k, slot.shape.name()));
            }
        }
        for (i, x) in x.iter().enumerate() {
            if moved[i].is_some() && slot.shape.inside(x) {
                return Err(StartInside::Stuck(i, k, slot.shape.name()));
            }
        }
    }
    Ok(())
}
