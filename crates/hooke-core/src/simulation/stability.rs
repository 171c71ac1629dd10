//! Step-size limits of explicit schemes, from the highest frequency of the spring network.
//!
//! `ω_max² ` is the largest eigenvalue of `M⁻¹ K`, with `K` the stiffness of the springs
//! linearised at the given positions (each spring contributes `ks u uᵀ` between its ends; the
//! geometric term `ks (1 - l/L)` is left out, it is small near rest). It is found by power
//! iteration from a fixed start vector, so the estimate is deterministic. Penalty colliders add
//! `kc` to every particle's diagonal, a bound for the particles that touch them, and the air
//! its stiffness at the strongest wind (see `diagonal_stiffness`). Damping limits the step
//! too: `γ_max`, the fastest damping rate (the largest eigenvalue of `M⁻¹ C`, found the
//! same way), must keep `dt γ_max` inside the
//! scheme's real stability interval.

use crate::collider::response::Response;
use crate::integrator::Integrator;
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, Vec3};

/// The highest angular frequency of a system, its fastest damping rate, and the explicit
/// step limits they imply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StabilityEstimate {
    /// Highest angular frequency `ω_max` in rad/s (zero for a system without springs).
    pub omega_max: f64,
    /// Fastest damping rate `γ_max` in 1/s: the largest eigenvalue of `M⁻¹ C` by power
    /// iteration (at most its Gershgorin bound), with `C` the velocity Jacobian of spring damping, drag, penalty damping and
    /// the air (linearised at the state's velocities against the strongest wind the air
    /// blows). An explicit scheme also needs `dt γ_max` inside its real stability interval.
    pub damping_max: f64,
}

/// Iterations of the power method; the estimate converges from below, and 60 iterations put
/// it within a few percent on the lattices and grids of the built-in scenes.
const POWER_ITERATIONS: usize = 60;

impl StabilityEstimate {
    /// Estimates `ω_max` for `model` at the particles' current positions.
    pub fn of(model: &Model, particles: &Particles) -> Self {
        let n = particles.len();
        let penalty_k = penalty_stiffness(model);
        let damping_max = damping_rate(model, particles);
        if n == 0 || (model.springs.is_empty() && penalty_k == 0.0 && model.air.is_none()) {
            return Self {
                omega_max: 0.0,
                damping_max,
            };
        }
        let diagonal = diagonal_stiffness(model, particles, penalty_k);
        let lambda = largest_eigenvalue(particles, &diagonal, |u, out| {
            for s in &model.springs {
                add_spring(
                    particles,
                    (s.i as usize, s.j as usize, s.rest, s.ks),
                    u,
                    out,
                );
            }
        });
        Self {
            omega_max: lambda.sqrt(),
            damping_max,
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
        let mut row = diagonal_stiffness(model, particles, penalty_k);
        for s in &model.springs {
            // Gershgorin: a material's bending springs have negative stiffness.
            row[s.i as usize] += 2.0 * s.ks.abs();
            row[s.j as usize] += 2.0 * s.ks.abs();
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
            damping_max: damping_rate(model, particles),
        }
    }

    /// The largest stable step of `integrator` in seconds: its
    /// [`Integrator::stability_radius`] over `ω_max`, and its real stability interval over
    /// `γ_max`, whichever is smaller (symplectic Euler: `ω² dt² + 2 γ dt ≤ 4` for the two
    /// together); infinite where the scheme has no such limit (backward
    /// Euler) or the system neither springs nor damping.
    pub fn max_dt(&self, integrator: Integrator) -> f64 {
        let radius = integrator.stability_radius();
        if !radius.is_finite() {
            return f64::INFINITY;
        }
        if integrator == Integrator::Symplectic {
            // Symplectic Euler on a mode `ẍ = -ω² x - γ ẋ` is stable exactly while
            // `ω² dt² + 2 γ dt ≤ 4` (its characteristic polynomial's roots on the unit disc);
            // a lattice's stiffest mode is also its most damped, so the two count together.
            let (w, g) = (self.omega_max, self.damping_max);
            let root = (g * g + 4.0 * w * w).sqrt();
            return if root + g == 0.0 {
                f64::INFINITY
            } else {
                4.0 / (g + root)
            };
        }
        let oscillation = if self.omega_max == 0.0 {
            f64::INFINITY
        } else {
            radius / self.omega_max
        };
        let damping = if self.damping_max == 0.0 {
            f64::INFINITY
        } else {
            real_interval(integrator) / self.damping_max
        };
        oscillation.min(damping)
    }
}

/// How far along the negative real axis `dt λ` may reach and the scheme stay stable: 2 for
/// the Euler schemes and midpoint (`|1 - z| ≤ 1`, `|1 - z + z²/2| ≤ 1`), 2.785 for RK4.
fn real_interval(integrator: Integrator) -> f64 {
    match integrator {
        Integrator::Rk4 => 2.785,
        _ => 2.0,
    }
}

/// [`StabilityEstimate::damping_max`]: the largest eigenvalue of `M⁻¹ C` by power iteration
/// (as `ω_max²` of `M⁻¹ K`), with `C` each spring's damping `kd u uᵀ` between its ends (a
/// zero-length spring's `kd I`) and on its diagonal what damps each particle alone: drag,
/// the penalty colliders' `dc` (the most a particle touching all of them feels) and the
/// air. The row sums' bound (Gershgorin's, counting every spring at a particle in every
/// direction) overstated a lattice's rate by three times, and with it called the built-in
/// jelly cube's own step unstable; it still bounds the estimate from above, which is kept
/// at most that.
fn damping_rate(model: &Model, p: &Particles) -> f64 {
    let penalty_dc: f64 = model
        .colliders
        .iter()
        .map(|c| match c.response {
            Response::Penalty { dc, .. } => dc,
            _ => 0.0,
        })
        .sum();
    let mut diagonal: Vec<f64> = p
        .mass
        .iter()
        .map(|&m| model.drag_on(m) + penalty_dc)
        .collect();
    // A triangle's force `½ ρ A C |u| u` changes by at most `ρ A C |u|` per unit of its
    // mean velocity; a corner moves that mean by a third and takes a third of it.
    add_air(model, p, &mut diagonal, |t| {
        t.rho_c * t.area * t.speed / 3.0
    });
    let mut row = diagonal.clone();
    for s in &model.springs {
        row[s.i as usize] += 2.0 * s.kd.abs();
        row[s.j as usize] += 2.0 * s.kd.abs();
    }
    let bound = row
        .iter()
        .zip(&p.mass)
        .zip(&p.inv_mass)
        .filter(|(_, inv)| **inv != 0.0)
        .map(|((k, m), _)| k / m)
        .fold(0.0, f64::max);
    if bound == 0.0 || model.springs.iter().all(|s| s.kd == 0.0) {
        return bound;
    }
    let damping: Vec<(u32, u32, f64, f64)> = model
        .springs
        .iter()
        .map(|s| (s.i, s.j, s.rest, s.kd))
        .collect();
    let rate = largest_eigenvalue(p, &diagonal, |u, out| {
        for &(i, j, rest, kd) in &damping {
            let (i, j) = (i as usize, j as usize);
            add_spring(p, (i, j, rest, kd), u, out);
        }
    });
    rate.min(bound)
}

/// The largest eigenvalue of `M⁻¹ (D + S)` by [`POWER_ITERATIONS`] of the power method from
/// a fixed start vector (deterministic), with `D` the diagonal `diagonal` and `S` what
/// `springs(u, out)` adds to `out`; the larger of the last Rayleigh quotient and growth
/// factor, since the quotient converges from below.
fn largest_eigenvalue(
    p: &Particles,
    diagonal: &[f64],
    springs: impl Fn(&[Vec3], &mut [Vec3]),
) -> f64 {
    let n = p.len();
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
        for ((o, x), k) in w.iter_mut().zip(&u).zip(diagonal) {
            *o = x * *k;
        }
        springs(&u, &mut w);
        for ((o, m), inv) in w.iter_mut().zip(&p.mass).zip(&p.inv_mass) {
            // Pinned particles do not move: their rows vanish.
            *o = if *inv == 0.0 { Vec3::zeros() } else { *o / *m };
        }
        lambda = parallel::dot(&u, &w);
        std::mem::swap(&mut u, &mut w);
    }
    let growth = parallel::dot(&u, &u).sqrt();
    lambda.max(growth).max(0.0)
}

/// Adds a spring's `k u uᵀ` between ends `i` and `j` (a zero-length spring's `k I`) applied
/// to `u` to `out`, `u` its direction at the particles' positions; a degenerate or overflowed
/// spring adds nothing.
fn add_spring(
    p: &Particles,
    (i, j, rest, k): (usize, usize, f64, f64),
    u: &[Vec3],
    out: &mut [Vec3],
) {
    // A zero-length spring (a material's bending) is `k I` in every direction: its
    // geometric term is not small.
    if rest == 0.0 {
        let f = (u[i] - u[j]) * k;
        out[i] += f;
        out[j] -= f;
        return;
    }
    let d = p.x[i] - p.x[j];
    let len = d.norm();
    // Degenerate springs have no direction; neither do springs at a particle that has
    // overflowed (a diverged state rebuilt by undoing the step).
    if !(len >= crate::forces::spring::DEGENERATE_LENGTH && len.is_finite()) {
        return;
    }
    let dir = d / len;
    let f = dir * (k * dir.dot(&(u[i] - u[j])));
    out[i] += f;
    out[j] -= f;
}

/// What each particle feels besides its springs, as a stiffness on the diagonal of `K`: the
/// penalty colliders' `kc` (the most a particle touching all of them feels) and the air's.
/// The air turns a triangle's force with its normal, which its corners turn: the force
/// `½ ρ A C |u| (u·n)` changes with a corner's position by at most `½ ρ C |u|² L` (`L` the
/// triangle's longest edge, `C = |C_d| + |C_l|`), and each corner takes its third of the
/// force, so the row of a corner adds that much per triangle, at the strongest wind.
fn diagonal_stiffness(model: &Model, p: &Particles, penalty_k: f64) -> Vec<f64> {
    let n = p.len();
    let mut row = vec![penalty_k; n];
    add_air(model, p, &mut row, |t| {
        0.5 * t.rho_c * t.speed * t.speed * t.longest
    });
    row
}

/// One aero triangle as the air's row sums see it.
struct AirTriangle {
    /// `ρ (|C_d| + |C_l|)`, kg/m³.
    rho_c: f64,
    /// Its mean speed plus the strongest wind the air blows, m/s.
    speed: f64,
    /// Its area, m², and longest edge, m.
    area: f64,
    longest: f64,
}

/// Adds `term` of each aero triangle (where finite) to each of its corners' rows; nothing
/// without air.
fn add_air(model: &Model, p: &Particles, row: &mut [f64], term: impl Fn(&AirTriangle) -> f64) {
    let Some(air) = &model.air else {
        return;
    };
    let n = p.len();
    let wind = air.wind.norm() + air.gust.map_or(0.0, |g| g.amplitude.norm());
    for surface in &model.aero {
        for t in &surface.triangles {
            let [a, b, c] = t.map(|i| i as usize);
            if a >= n || b >= n || c >= n {
                continue;
            }
            let (ab, bc, ca) = (p.x[b] - p.x[a], p.x[c] - p.x[b], p.x[a] - p.x[c]);
            let mean = (p.v[a] + p.v[b] + p.v[c]) * (1.0 / 3.0);
            let k = term(&AirTriangle {
                rho_c: air.density * (surface.drag.abs() + surface.lift.abs()),
                speed: mean.norm() + wind,
                area: 0.5 * ab.cross(&(p.x[c] - p.x[a])).norm(),
                longest: ab.norm().max(bc.norm()).max(ca.norm()),
            });
            if k.is_finite() {
                for i in [a, b, c] {
                    row[i] += k;
                }
            }
        }
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

fn normalise(u: &mut [Vec3]) {
    let norm = parallel::dot(u, u).sqrt();
    if norm > 0.0 {
        for x in u.iter_mut() {
            *x /= norm;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forces::spring::{Spring, SpringKind};

    /// A material's bending element (three zero-length springs, `2k`, `2k`, `-k`) on three
    /// free unit masses in a straight line is the matrix `k (1, -2, 1)ᵀ(1, -2, 1) ⊗ I`, whose
    /// largest eigenvalue is `6k` in every direction: the estimate finds `ω_max = √(6k)`,
    /// and the bound is at least that.
    #[test]
    fn a_bending_element_counts_in_every_direction() {
        let mut p = Particles::default();
        for x in [0.0, 0.1, 0.2] {
            p.push(Vec3::new(x, 0.0, 0.0), Vec3::zeros(), 1.0);
        }
        let k = 50.0;
        let spring = |i: u32, j: u32, ks: f64| Spring {
            i,
            j,
            rest: 0.0,
            ks,
            kd: 0.0,
            kind: SpringKind::Bend,
        };
        let model = Model {
            springs: vec![
                spring(0, 1, 2.0 * k),
                spring(1, 2, 2.0 * k),
                spring(0, 2, -k),
            ],
            ..Model::default()
        };
        let exact = (6.0 * k).sqrt();
        let estimate = StabilityEstimate::of(&model, &p).omega_max;
        assert!(
            (estimate / exact - 1.0).abs() < 1e-6,
            "{estimate} vs {exact}"
        );
        assert!(StabilityEstimate::bound(&model, &p).omega_max >= exact);
    }
}
