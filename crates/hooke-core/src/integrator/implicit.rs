//! Implicit (backward) Euler, one Newton step linearised at the current state (Baraff &
//! Witkin 1998), solved with preconditioned conjugate gradients.
//!
//! With `K` and `D` the springs' positive semi-definite stiffness and damping blocks (see
//! [`blocks::spring_blocks`]), the velocity change solves
//!
//! `(M + dt·drag·I + dt·D + dt²·K) Δv = dt (f₀ - dt K v₀)`,
//!
//! then `v' = v + Δv`, `x' = x + dt v'`. The matrix is symmetric positive definite and never
//! assembled: CG multiplies by it spring by spring through the same fixed-order partitions
//! as the forces, so results are bit-identical on any thread count. Pinned particles, and
//! particles held by a stick response, are filtered out of the system (their rows and
//! columns are zero, `Δv = 0`): Baraff and Witkin's constraint filter, which keeps a
//! tablecloth's stuck particles from being dragged through the top by long steps. The force
//! field and penalty colliders enter through `f₀` only: their derivatives are not linearised.

use super::blocks::{self, Sym3};
use super::{StepReport, Workspace};
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, Vec3};

/// Backward Euler is stable for every step.
pub(super) const STABILITY_RADIUS: f64 = f64::INFINITY;

/// Relative residual `|r| / |b|` at which CG stops.
pub(super) const CG_TOLERANCE: f64 = 1e-8;
/// CG iterations at most per step; the step then takes the best iterate.
pub(super) const CG_MAX_ITERATIONS: usize = 500;

/// Buffers of the implicit step, kept between steps.
#[derive(Clone, Debug, Default)]
pub(crate) struct ImplicitBuffers {
    /// Per spring (assembly order): `[K, D]`.
    blocks: Vec<[Sym3; 2]>,
    /// Per spring: `dt² K + dt D`.
    system: Vec<Sym3>,
    /// Per particle: the inverse diagonal block of the system (zero for filtered particles).
    preconditioner: Vec<Sym3>,
    /// CG iterations of the last step.
    pub(crate) iterations: usize,
}

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
    held: &[bool],
) -> StepReport {
    let n = p.len();
    ws.x0.copy_from_slice(&p.x);
    let cancel = ws.cancel;
    let buffers = &mut ws.implicit;
    let asm = &mut ws.assembly;
    let inv_mass = &p.inv_mass;
    let fixed = |i: usize| inv_mass[i] == 0.0 || held.get(i).copied().unwrap_or(false);

    // Forces at the current state.
    let [f0, b, dv, r] = &mut ws.kv;
    // Air is taken at the step's start and left out of the Jacobian (docs/physics.md §4).
    let air = ws
        .air
        .evaluate(model.air.as_ref(), &model.aero, &p.x, &p.v, t);
    asm.forces(model, &p.mass, (&p.x, &p.v), air, f0, |_, f| f);

    // Jacobian blocks and the system's per-spring blocks.
    blocks::spring_blocks(asm, &p.x, &mut buffers.blocks);
    buffers.system.clear();
    buffers.system.extend(
        buffers
            .blocks
            .iter()
            .map(|[k, d]| k.scale(dt * dt).plus(&d.scale(dt))),
    );

    // Right-hand side b = dt (f0 - dt K v0), zero at filtered particles.
    {
        let (blocks, v) = (&buffers.blocks, &p.v);
        asm.scatter_pairs(|k, i, j| blocks[k][0].mul(&(v[i] - v[j])));
    }
    {
        let f0 = &*f0;
        asm.map_gathered(b, |i, kv| {
            if fixed(i) {
                Vec3::zeros()
            } else {
                (f0[i] - kv * dt) * dt
            }
        });
    }

    // Block-Jacobi preconditioner: the inverse of each particle's diagonal block.
    // Each particle's mass and drag on the diagonal.
    let inertia = |m: f64| m + dt * model.drag_on(m);
    buffers.preconditioner.clear();
    buffers
        .preconditioner
        .extend((0..n).map(|i| Sym3::default().plus_identity(inertia(p.mass[i]))));
    for (k, c) in buffers.system.iter().enumerate() {
        let [i, j] = asm.ends(k);
        buffers.preconditioner[i] = buffers.preconditioner[i].plus(c);
        buffers.preconditioner[j] = buffers.preconditioner[j].plus(c);
    }
    for (i, m) in buffers.preconditioner.iter_mut().enumerate() {
        *m = if fixed(i) {
            Sym3::default()
        } else {
            m.inverse().unwrap_or_default()
        };
    }

    // Preconditioned CG on A Δv = b, A = M + dt·drag + Σ system blocks, pinned and held rows filtered.
    let [d, q, z, _] = &mut ws.kx;
    let system = &buffers.system;
    let mass = &p.mass;
    let multiply = |asm: &mut crate::assembly::Assembly, from: &[Vec3], to: &mut [Vec3]| {
        asm.scatter_pairs(|k, i, j| system[k].mul(&(from[i] - from[j])));
        asm.map_gathered(to, |i, row| {
            if fixed(i) {
                Vec3::zeros()
            } else {
                from[i] * inertia(mass[i]) + row
            }
        });
    };
    let precondition = |r: &[Vec3], z: &mut [Vec3]| {
        let m = &buffers.preconditioner;
        parallel::for_each(z, |i, z| *z = m[i].mul(&r[i]));
    };
    dv.fill(Vec3::zeros());
    r.copy_from_slice(b);
    let b_norm = parallel::dot(b, b).sqrt();
    let mut iterations = 0;
    if b_norm > 0.0 {
        precondition(r, z);
        d.copy_from_slice(z);
        let mut delta = parallel::dot(r, z);
        while iterations < CG_MAX_ITERATIONS {
            // A product of a million particles' springs takes a quarter of a second and a
            // step may run hundreds: Ctrl-C ends it here, unsolved (an atomic load an
            // iteration), and the caller stops the run at its last complete frame.
            if super::cancelled(cancel) {
                break;
            }
            iterations += 1;
            multiply(asm, d, q);
            let curvature = parallel::dot(d, q);
            // Zero or NaN curvature: the system is singular here; keep the best iterate.
            if curvature.is_nan() || curvature <= 0.0 {
                break;
            }
            let alpha = delta / curvature;
            parallel::axpy(dv, alpha, d);
            parallel::axpy(r, -alpha, q);
            if parallel::dot(r, r).sqrt() <= CG_TOLERANCE * b_norm {
                break;
            }
            precondition(r, z);
            let next = parallel::dot(r, z);
            let beta = next / delta;
            delta = next;
            parallel::for_each(d, |i, d| *d = z[i] + *d * beta);
        }
    }
    buffers.iterations = iterations;

    // The springs' terms of A cancel in pairs, so Σ (A Δv)_i = Σ m_i Δv_i (+ drag) and the
    // momentum change equals Σ b - Σ r. Spreading the leftover residual Σ r over the free
    // particles as one uniform velocity makes the step conserve momentum exactly, as the
    // explicit schemes do, at a cost below the CG tolerance.
    let residual: Vec3 = r.iter().sum();
    let free_mass: f64 = (0..n)
        .filter(|&i| !fixed(i))
        .map(|i| inertia(p.mass[i]))
        .sum();
    if free_mass > 0.0 {
        let shift = residual / free_mass;
        parallel::for_each(dv, |i, dv| {
            if !fixed(i) {
                *dv += shift;
            }
        });
    }

    let dv = &*dv;
    super::for_blocks(&mut p.x, &mut p.v, |start, x, v| {
        for k in 0..x.len() {
            v[k] += dv[start + k];
            x[k] += v[k] * dt;
        }
    });
    StepReport::SAVED
}
