//! Per-frame summary figures of a state.

use crate::model::Model;
use crate::particles::{Particles, Vec3};

/// Figures that describe one frame at a glance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Kinetic energy `Σ m v² / 2` in joules.
    pub kinetic: f64,
    /// Potential energy (springs, gravity with zero at y = 0, penalty springs) in joules.
    pub potential: f64,
    /// Lower corner of the particles' bounding box, metres.
    pub min: Vec3,
    /// Upper corner of the particles' bounding box, metres.
    pub max: Vec3,
    /// Highest particle speed in m/s.
    pub max_speed: f64,
    /// Deepest penetration into any collider, metres.
    pub max_penetration: f64,
}

impl Summary {
    /// Computes the summary of `particles` under `model`.
    pub fn of(model: &Model, particles: &Particles) -> Self {
        let (min, max) = bounds(&particles.x);
        Self {
            kinetic: kinetic(particles),
            potential: model.potential_energy(&particles.mass, &particles.x),
            min,
            max,
            max_speed: particles.v.iter().map(|v| v.norm()).fold(0.0, f64::max),
            max_penetration: model.max_penetration(&particles.x),
        }
    }
}

/// Kinetic energy `Σ m v² / 2` of the free particles, joules.
pub(crate) fn kinetic(p: &Particles) -> f64 {
    p.v.iter()
        .zip(&p.mass)
        .zip(&p.inv_mass)
        .filter(|(_, inv)| **inv != 0.0)
        .map(|((v, m), _)| 0.5 * m * v.norm_squared())
        .sum()
}

/// The lower and upper corners of the points' bounding box (infinite ones for none).
pub(crate) fn bounds(x: &[Vec3]) -> (Vec3, Vec3) {
    let inf = Vec3::repeat(f64::INFINITY);
    x.iter()
        .fold((inf, -inf), |(lo, hi), x| (lo.inf(x), hi.sup(x)))
}
