//! The force model of a system: everything that is constant during a run.

use crate::collider::{Collider, Contact};
use crate::force_field::ForceField;
use crate::particles::Vec3;
use crate::response::Response;
use crate::spring::Spring;

/// A collider together with the response it triggers.
#[derive(Debug)]
pub struct ColliderSlot {
    /// The shape.
    pub shape: Box<dyn Collider>,
    /// What it does to particles that violate it.
    pub response: Response,
}

/// Springs, external forces and colliders, and the per-particle masses they act on.
///
/// Forces are evaluated per SPEC §1. Each spring's force is computed once into a buffer and
/// then *gathered* per particle in a fixed order (its springs in index order), so that the sum
/// is the same bits however the work is split.
#[derive(Debug, Default)]
pub struct Model {
    /// Every spring of the system.
    pub springs: Vec<Spring>,
    /// Gravitational acceleration in m/s², applied as the force `m g`.
    pub gravity: Vec3,
    /// Linear drag in N·s/m (force `-drag v` on every particle); zero disables it.
    pub drag: f64,
    /// An optional force field (jello worlds).
    pub field: Option<ForceField>,
    /// Colliders, each with its response.
    pub colliders: Vec<ColliderSlot>,
}

/// For each particle, the springs touching it and the sign of their force on it, in spring
/// order (compressed sparse rows). Derived from a model's springs; the integrators' workspace
/// keeps one.
#[derive(Clone, Debug, Default)]
pub struct Adjacency {
    start: Vec<u32>,
    /// Spring index, with the top bit set when the particle is the spring's `j` end.
    entries: Vec<u32>,
}

const J_END: u32 = 1 << 31;

impl Adjacency {
    /// Builds the adjacency of `springs` over `particles` particles.
    ///
    /// # Panics
    /// If a spring names a particle that does not exist (a builder bug, not user input: scene
    /// loaders validate indices first).
    pub fn new(particles: usize, springs: &[Spring]) -> Self {
        for (k, s) in springs.iter().enumerate() {
            assert!(
                (s.i as usize) < particles && (s.j as usize) < particles,
                "spring {k} names particle {} or {} of {particles}",
                s.i,
                s.j
            );
        }
        let mut count = vec![0u32; particles + 1];
        for s in springs {
            count[s.i as usize + 1] += 1;
            count[s.j as usize + 1] += 1;
        }
        for p in 0..particles {
            count[p + 1] += count[p];
        }
        let start = count.clone();
        let mut fill = count;
        let mut entries = vec![0u32; 2 * springs.len()];
        for (k, s) in springs.iter().enumerate() {
            let k = k as u32;
            entries[fill[s.i as usize] as usize] = k;
            fill[s.i as usize] += 1;
            entries[fill[s.j as usize] as usize] = k | J_END;
            fill[s.j as usize] += 1;
        }
        Self { start, entries }
    }

    /// Whether this adjacency was built for this many particles and springs.
    pub fn fits(&self, particles: usize, springs: usize) -> bool {
        self.start.len() == particles + 1 && self.entries.len() == 2 * springs
    }
}

impl Model {
    /// Computes the acceleration of every particle for positions `x` and velocities `v`.
    ///
    /// `adjacency` must be built from this model's springs; `spring_force` is scratch space
    /// of one entry per spring. Pinned particles (`inv_mass == 0`) get zero acceleration.
    #[allow(clippy::too_many_arguments)]
    pub fn accelerations(
        &self,
        adjacency: &Adjacency,
        mass: &[f64],
        inv_mass: &[f64],
        x: &[Vec3],
        v: &[Vec3],
        spring_force: &mut [Vec3],
        a: &mut [Vec3],
    ) {
        for (f, s) in spring_force.iter_mut().zip(&self.springs) {
            let (i, j) = (s.i as usize, s.j as usize);
            *f = s.force(&x[i], &x[j], &v[i], &v[j]);
        }
        for (p, out) in a.iter_mut().enumerate() {
            if inv_mass[p] == 0.0 {
                *out = Vec3::zeros();
                continue;
            }
            let mut f = self.external_force(mass[p], &x[p], &v[p]);
            let range = adjacency.start[p] as usize..adjacency.start[p + 1] as usize;
            for &e in &adjacency.entries[range] {
                let sf = spring_force[(e & !J_END) as usize];
                if e & J_END == 0 {
                    f += sf;
                } else {
                    f -= sf;
                }
            }
            *out = f / mass[p];
        }
    }

    /// Every force on one particle except its springs': gravity, field, drag, penalties.
    #[inline]
    pub fn external_force(&self, mass: f64, x: &Vec3, v: &Vec3) -> Vec3 {
        let mut f = self.gravity * mass;
        if let Some(field) = &self.field {
            f += field.sample(x);
        }
        if self.drag != 0.0 {
            f -= v * self.drag;
        }
        for slot in &self.colliders {
            if slot.response.is_force() {
                slot.shape
                    .contacts(x, &mut |c: Contact| f += slot.response.penalty_force(&c, v));
            }
        }
        f
    }

    /// Applies the velocity-level responses (restitution, stick) after a full step. `x0` are
    /// the positions at the start of the step, for the crossing test of thin colliders.
    pub fn resolve_contacts(&self, inv_mass: &[f64], x0: &[Vec3], x: &mut [Vec3], v: &mut [Vec3]) {
        if self.colliders.iter().all(|c| c.response.is_force()) {
            return;
        }
        for p in 0..x.len() {
            if inv_mass[p] == 0.0 {
                continue;
            }
            for slot in self.colliders.iter().filter(|c| !c.response.is_force()) {
                let start = x[p];
                let mut touched = false;
                slot.shape.contacts(&start, &mut |c| {
                    touched = true;
                    slot.response.resolve(&c, &mut x[p], &mut v[p]);
                });
                if !touched && let Some(c) = slot.shape.crossing(&x0[p], &start) {
                    slot.response.resolve(&c, &mut x[p], &mut v[p]);
                }
            }
        }
    }

    /// Total potential energy in joules: springs, gravity (zero at the origin) and penalty
    /// springs. The force field has no potential in general and is left out.
    pub fn potential_energy(&self, mass: &[f64], x: &[Vec3]) -> f64 {
        let springs: f64 = self
            .springs
            .iter()
            .map(|s| s.energy(&x[s.i as usize], &x[s.j as usize]))
            .sum();
        let gravity: f64 = x
            .iter()
            .zip(mass)
            .map(|(x, m)| -m * self.gravity.dot(x))
            .sum();
        let mut penalty = 0.0;
        for slot in &self.colliders {
            if let Response::Penalty { kc, .. } = slot.response {
                for p in x {
                    slot.shape
                        .contacts(p, &mut |c| penalty += 0.5 * kc * c.depth * c.depth);
                }
            }
        }
        springs + gravity + penalty
    }

    /// The deepest penetration of any particle into any collider, in metres.
    pub fn max_penetration(&self, x: &[Vec3]) -> f64 {
        self.colliders
            .iter()
            .flat_map(|slot| x.iter().map(|p| slot.shape.depth(p)))
            .fold(0.0, f64::max)
    }
}
