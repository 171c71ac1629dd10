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
        let kinetic = particles
            .v
            .iter()
            .zip(&particles.mass)
            .zip(&particles.inv_mass)
            .filter(|(_, inv)| **inv != 0.0)
            .map(|((v, m), _)| 0.5 * m * v.norm_squared())
            .sum();
        let inf = Vec3::repeat(f64::INFINITY);
        let (min, max) = particles
            .x
            .iter()
            .fold((inf, -inf), |(lo, hi), x| (lo.inf(x), hi.sup(x)));
        Self {
            kinetic,
            potential: model.potential_energy(&particles.mass, &particles.x),
            min,
            max,
            max_speed: particles.v.iter().map(|v| v.norm()).fold(0.0, f64::max),
            max_penetration: model.max_penetration(&particles.x),
        }
    }
}
