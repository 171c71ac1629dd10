//! Step-size limits of explicit schemes, from the highest frequency of the spring network.
//!
//! `ω_max² ` is the largest eigenvalue of `M⁻¹ K`, with `K` the stiffness of the springs
//! linearised at the given positions (each spring contributes `ks u uᵀ` between its ends; the
//! geometric term `ks (1 - l/L)` is left out, it is small near rest). It is found by power
//! iteration from a fixed start vector, so the estimate is deterministic. Penalty colliders add
//! `kc` to every particle's diagonal, a bound for the particles that touch them.

use crate::collider::response::Response;
use crate::integrator::Integrator;
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, Vec3};

/// The highest angular frequency of a system and the explicit step limits it implies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StabilityEstimate {
    /// Highest angular frequency `ω_max` in rad/s (zero for a system without springs).
    pub omega_max: f64,
}

/// Iterations of the power method; the estimate converges from below, and 60 iterations put
/// it within a few percent on the lattices and grids of the built-in scenes.
const POWER_ITERATIONS: usize = 60;

impl StabilityEstimate {
    /// Estimates `ω_max` for `model` at the particles' current positions.
    pub fn of(model: &Model, particles: &Particles) -> Self {
        let n = particles.len();
        let penalty_k = penalty_stiffness(model);
        if n == 0 || (model.springs.is_empty() && penalty_k == 0.0) {
            return Self { omega_max: 0.0 };
        }
        // A fixed, non-symmetric start vector so no mode is missed by symmetry.
        let mut u: Vec<Vec3> = (0..n)
            .map(|i| {
                let t = i as f64;
                Vec3::new(
                    (t * 0.7548).sin() + 1.1,
                    (t * 0.5698).cos() + 1.3,
                    (t * 0.3141).sin() + 1.7,
                )
            })
            .collect();
        let mut w = vec![Vec3::zeros(); n];
        let mut lambda = 0.0;
        for _ in 0..POWER_ITERATIONS {
            normalise(&mut u);
            apply(model, particles, penalty_k, &u, &mut w);
            lambda = parallel::dot(&u, &w);
            std::mem::swap(&mut u, &mut w);
        }
        // The Rayleigh quotient converges from below; the last growth factor bounds the error.
        let growth = parallel::dot(&u, &u).sqrt();
        Self {
            omega_max: lambda.max(growth).max(0.0).sqrt(),
        }
    }

    /// An upper bound on `ω_max` that needs no geometry (for a state that has overflowed):
    /// by Gershgorin's theorem no eigenvalue of `M⁻¹K` exceeds the largest row sum,
    /// `(2 Σ ks + kc) / m` over the springs at a particle. Never below [`Self::of`].
    ///
    /// ```
    /// use hooke_core::{Model, Particles, Spring, SpringKind, StabilityEstimate, Vec3};
    /// let mut p = Particles::default();
    /// p.push(Vec3::zeros(), Vec3::zeros(), 1.0);
    /// p.push(Vec3::new(1.0, 0.0, 0.0), Vec3::zeros(), 1.0);
    /// let model = Model {
    ///     springs: vec![Spring { i: 0, j: 1, rest: 1.0, ks: 100.0, kd: 0.0, kind: SpringKind::Structural }],
    ///     ..Model::default()
    /// };
    /// // Two unit masses on a spring of 100 N/m: ω = √(2 · 100); the bound is √(2 · 100) too.
    /// let exact = StabilityEstimate::of(&model, &p).omega_max;
    /// let bound = StabilityEstimate::bound(&model, &p).omega_max;
    /// assert!((exact - 200f64.sqrt()).abs() < 1e-9);
    /// assert!(bound >= exact);
    /// ```
    pub fn bound(model: &Model, particles: &Particles) -> Self {
        let penalty_k = penalty_stiffness(model);
        let mut row = vec![penalty_k; particles.len()];
        for s in &model.springs {
            row[s.i as usize] += 2.0 * s.ks;
            row[s.j as usize] += 2.0 * s.ks;
        }
        let lambda = row
            .iter()
            .zip(&particles.mass)
            .zip(&particles.inv_mass)
            .filter(|(_, inv)| **inv != 0.0)
            .map(|((k, m), _)| k / m)
            .fold(0.0, f64::max);
        Self {
            omega_max: lambda.sqrt(),
        }
    }

    /// The largest stable step of `integrator` in seconds: its
    /// [`Integrator::stability_radius`] over `ω_max`; infinite where the scheme has no such
    /// limit (backward Euler) or the system no springs.
    pub fn max_dt(&self, integrator: Integrator) -> f64 {
        if self.omega_max == 0.0 {
            return f64::INFINITY;
        }
        integrator.stability_radius() / self.omega_max
    }
}

/// The penalty colliders' stiffness, summed: the most a particle touching all of them feels.
fn penalty_stiffness(model: &Model) -> f64 {
    model
        .colliders
        .iter()
        .map(|c| match c.response {
            Response::Penalty { kc, .. } => kc,
            _ => 0.0,
        })
        .sum()
}

fn apply(model: &Model, p: &Particles, penalty_k: f64, u: &[Vec3], out: &mut [Vec3]) {
    for (o, x) in out.iter_mut().zip(u) {
        *o = x * penalty_k;
    }
    for s in &model.springs {
        let (i, j) = (s.i as usize, s.j as usize);
        let d = p.x[i] - p.x[j];
        let len = d.norm();
        // Degenerate springs have no direction; neither do springs at a particle that has
        // overflowed (a diverged state rebuilt by undoing the step).
        if !(len >= crate::forces::spring::DEGENERATE_LENGTH && len.is_finite()) {
            continue;
        }
        let dir = d / len;
        let f = dir * (s.ks * dir.dot(&(u[i] - u[j])));
        out[i] += f;
        out[j] -= f;
    }
    for ((o, m), inv) in out.iter_mut().zip(&p.mass).zip(&p.inv_mass) {
        // Pinned particles do not move: their rows of M⁻¹K vanish.
        *o = if *inv == 0.0 { Vec3::zeros() } else { *o / *m };
    }
}

fn normalise(u: &mut [Vec3]) {
    let norm = parallel::dot(u, u).sqrt();
    if norm > 0.0 {
        for x in u.iter_mut() {
            *x /= norm;
        }
    }
}
