//! Particle storage: flat arrays, one entry per particle.

use nalgebra::Vector3;

/// A 3-vector of `f64`, the unit of every position, velocity and force in Hooke.
pub type Vec3 = Vector3<f64>;

/// Positions beyond this many metres from the origin count as divergence: no scene in Hooke
/// is larger than a few metres, and an explicit blow-up passes this bound within a few steps.
/// Scene and mesh readers refuse coordinates beyond it for the same reason.
pub const SANE_BOUND: f64 = 1.0e6;

/// The particles of a system, stored as parallel flat arrays (structure of arrays).
///
/// Positions are in metres, velocities in m/s, masses in kg. A particle whose inverse mass is
/// zero is *pinned*: it never moves and keeps zero velocity. Its `mass` stays finite so that
/// forces such as `m g` stay finite too.
///
/// ```
/// use hooke_core::{Particles, Vec3};
/// let mut p = Particles::default();
/// let a = p.push(Vec3::new(0.0, 1.0, 0.0), Vec3::zeros(), 0.1);
/// p.pin(a);
/// assert!(p.is_pinned(a));
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    /// Positions in metres.
    pub x: Vec<Vec3>,
    /// Velocities in m/s.
    pub v: Vec<Vec3>,
    /// Masses in kg (always finite and positive, pinned or not).
    pub mass: Vec<f64>,
    /// Inverse masses in 1/kg; zero means pinned.
    pub inv_mass: Vec<f64>,
}

impl Particles {
    /// Adds a free particle and returns its index.
    pub fn push(&mut self, x: Vec3, v: Vec3, mass: f64) -> usize {
        self.x.push(x);
        self.v.push(v);
        self.mass.push(mass);
        self.inv_mass.push(1.0 / mass);
        self.x.len() - 1
    }

    /// Pins particle `i`: zero inverse mass and zero velocity from now on.
    pub fn pin(&mut self, i: usize) {
        self.inv_mass[i] = 0.0;
        self.v[i] = Vec3::zeros();
    }

    /// Whether particle `i` is pinned.
    pub fn is_pinned(&self, i: usize) -> bool {
        self.inv_mass[i] == 0.0
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Centre of mass of all particles (pinned ones included), in metres.
    pub fn centroid(&self) -> Vec3 {
        let total: f64 = self.mass.iter().sum();
        let weighted = self
            .x
            .iter()
            .zip(&self.mass)
            .fold(Vec3::zeros(), |acc, (x, m)| acc + x * *m);
        weighted / total
    }
}
