//! Newton's method on the implicit-Euler step (docs/physics.md §4.2), after IPC (Li et al.
//! 2020): the step's energy — the one block descent minimises one particle at a time
//! (`vbd/local.rs`) — minimised over every particle at once.
//!
//! * Each iteration assembles the energy's gradient and a positive semi-definite Hessian:
//!   each spring's block with its part across the spring clamped at zero when compressed
//!   (Choi & Ko 2002), the contacts' normal and friction blocks, inertia, drag and
//!   attachments.
//! * It solves the Newton system with conjugate gradients to a residual of [`CG_TOLERANCE`]
//!   of the right-hand side's, preconditioned by the inverse 3×3 diagonal blocks or by the
//!   springs' part factored with faer's sparse Cholesky (`factor.rs`), chosen by counted
//!   cost ([`solve`]).
//! * A backtracking line search halves the step until the energy falls, every trial point
//!   clipped to its particle's bounds from the last detection (block descent's, with its
//!   re-detection when a hundredth of the particles wait at them): no surface crosses a
//!   collider or another surface, at any step. A search that finds no lower energy does not
//!   move. The detections within a step centre each ball where its particle is
//!   ([`Centres::Detected`]), so that the current iterate is always a trial the search
//!   may keep.
//! * The step ends when its last Newton step (the search direction, before the line search)
//!   moved no free particle faster than the tolerance of its [`StopRule`] (IPC's rule), or
//!   at its iteration budget.
//!
//! Dot products and energies are sums over fixed blocks added in order, and every row is
//! one particle's: the same bits on any thread count.

mod factor;

use super::vbd::detect::Centres;
use super::vbd::local::{Local, friction_stiffness};
use super::vbd::{clip, finish, keep_momentum, prepare};
use super::{StepReport, StopRule, Sym3, Workspace};
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, Vec3};
use rayon::prelude::*;

/// Newton's step is implicit Euler: stable for every step.
pub(super) const STABILITY_RADIUS: f64 = f64::INFINITY;
/// Conjugate gradients stop at this share of the right-hand side's norm (an inexact Newton
/// step: the line search and the next iteration make up the rest).
pub(super) const CG_TOLERANCE: f64 = 1e-4;
/// Conjugate-gradient iterations at most per Newton iteration.
pub(super) const CG_MAX_ITERATIONS: usize = 2000;
/// Halvings of the line search before it gives up and keeps the iterate where it is.
const HALVINGS: usize = 12;
/// A line search that ends below this share of the Newton step has stalled.
const STALLED: f64 = 0.01;
/// The share of the free particles that must wait at their bounds before an iteration
/// detects again, as block descent's.
const DETECT_SHARE: f64 = 0.01;
/// Particles per parallel chunk.
const CHUNK: usize = 512;
/// Conjugate-gradient iterations between two looks at the cancel question (each a pass
/// over the springs and a preconditioner solve).
const CANCEL_EVERY: usize = 8;

/// Newton's buffers, kept between steps.
#[derive(Clone, Debug, Default)]
pub(crate) struct NewtonBuffers {
    /// Per particle: its force (the right-hand side) and diagonal block.
    force: Vec<Vec3>,
    diagonal: Vec<Sym3>,
    /// The inverse diagonal blocks (the preconditioner).
    inverse: Vec<Sym3>,
    /// Per spring end, in the graph's order: the spring's Hessian block.
    springs: Vec<Sym3>,
    /// Per detected pair: its weights, their count, and its normal and tangential block.
    pairs: Vec<Option<([f64; 4], usize, Sym3)>>,
    /// The Newton direction, conjugate-gradient vectors and the trial point.
    direction: Vec<Vec3>,
    r: Vec<Vec3>,
    z: Vec<Vec3>,
    q: Vec<Vec3>,
    s: Vec<Vec3>,
    trial: Vec<Vec3>,
    pinned: Vec<bool>,
    /// Per particle: whether the accepted trial point was clipped to its bound.
    held: Vec<bool>,
    /// The springs' part of the system, factored: the preconditioner.
    factor: factor::Factor,
    /// The energy's partial sums, and the contact couplings handed to the factor.
    parts: Vec<f64>,
    couplings: Vec<(usize, usize, Sym3)>,
    /// Conjugate-gradient iterations of the last step, all Newton iterations summed.
    pub(crate) cg_iterations: usize,
}

pub(super) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    let mut clock = super::Lap::start();
    let rule = ws.stop.unwrap_or(StopRule::NEWTON);
    let cancel = ws.cancel;
    let n = p.len();
    prepare(model, p, (t, dt), ws, &mut clock);
    let (b, nb) = (&mut ws.vbd, &mut ws.newton);
    b.times.detection += clock.lap();
    nb.pinned.clear();
    nb.pinned.extend((0..n).map(|i| p.is_pinned(i)));
    nb.held.clear();
    nb.held.resize(n, false);
    let free = nb.pinned.iter().filter(|&&pin| !pin).count();
    let enough = ((DETECT_SHARE * free as f64).ceil() as usize).max(1);
    for v in [
        &mut nb.force,
        &mut nb.direction,
        &mut nb.r,
        &mut nb.z,
        &mut nb.q,
        &mut nb.s,
        &mut nb.trial,
    ] {
        v.resize(n, Vec3::zeros());
    }
    nb.diagonal.resize(n, Sym3::default());
    nb.inverse.resize(n, Sym3::default());
    let start = &ws.x0;
    let (mut iterations, mut converged, mut last_move) = (0, false, 0.0);
    nb.cg_iterations = 0;
    while iterations < rule.iterations && !super::cancelled(cancel) {
        iterations += 1;
        let local = Local {
            model,
            graph: &b.graph,
            detection: &b.detection,
            mass: &p.mass,
            start,
            target: &b.target,
            dt,
        };
        assemble(&local, &p.x, nb);
        nb.cg_iterations += solve(&local, nb, model.springs.len(), cancel);
        b.times.sweeps += clock.lap();
        // Backtracking on the energy, every trial point clipped to its bounds.
        let before = local.energy(&p.x, &p.x, &nb.pinned, &mut nb.parts);

        let mut alpha = 1.0;
        let mut held = 0;
        for halving in 0..=HALVINGS {
            held = 0;
            for i in 0..n {
                nb.trial[i] = if nb.pinned[i] {
                    p.x[i]
                } else {
                    let (to, c) = clip(
                        &b.detection,
                        &b.detected,
                        i,
                        p.x[i] + nb.direction[i] * alpha,
                    );
                    nb.held[i] = c;
                    held += usize::from(c);
                    to
                };
            }
            if local.energy(&nb.trial, &p.x, &nb.pinned, &mut nb.parts) <= before {
                break;
            }
            if halving == HALVINGS {
                // No share of the step lowers the energy: taking it anyway adds energy each
                // iteration (a sleeve landing on its own folds went from 0.066 J to 0.25 J
                // within one step so, docs/physics.md §4.2).
                nb.trial.copy_from_slice(&p.x);
                alpha = 0.0;
                break;
            }
            alpha *= 0.5;
        }

        // IPC's rule reads the Newton step itself, not the line search's share of it: a
        // search that stalls on a small step has not converged.
        // Particles held at their bounds wait for the next detection, as in block descent.
        let largest = (0..n)
            .filter(|&i| !nb.pinned[i] && !nb.held[i])
            .map(|i| nb.direction[i].norm())
            .fold(0.0, f64::max);
        p.x.copy_from_slice(&nb.trial);
        b.times.acceleration += clock.lap();
        last_move = largest;
        let settled = largest <= rule.tolerance * dt;
        if settled && held == 0 {
            converged = true;
            break;
        }
        // A direction that no share of lowers the energy, with no bound in the way, is the
        // same at the next iteration: the step ends here, unsolved.
        if alpha == 0.0 && held == 0 {
            break;
        }
        // Detect again when enough particles wait at their bounds, when only they are left
        // to move, or when they stall the line search (a Newton step clipped at the bounds
        // need not be a descent).
        let stalled = alpha < STALLED;
        if (held >= enough || ((settled || stalled) && held > 0)) && iterations < rule.iterations {
            b.detection.detect(
                model,
                p,
                &b.graph,
                (&p.x, &b.target),
                (dt, Centres::Detected),
            );
            b.detected.copy_from_slice(&p.x);
            b.detections += 1;
            b.times.detection += clock.lap();
        }
    }
    finish(b, (iterations, converged, last_move), p, start, dt);
    keep_momentum(model, p, start, &b.momentum, dt);
    StepReport::SAVED
}

/// The Newton system at `x`: each particle's force and diagonal block (block descent's
/// rows), each spring's block and each contact pair's.
fn assemble(local: &Local<'_>, x: &[Vec3], nb: &mut NewtonBuffers) {
    let pinned = &nb.pinned;
    nb.force
        .par_chunks_mut(CHUNK)
        .zip(nb.diagonal.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(c, (f, h))| {
            for k in 0..f.len() {
                let i = c * CHUNK + k;
                (f[k], h[k]) = if pinned[i] {
                    (Vec3::zeros(), Sym3::default().plus_identity(1.0))
                } else {
                    local.row(i, x)
                };
            }
        });
    let diagonal = &nb.diagonal;
    nb.inverse
        .par_iter_mut()
        .enumerate()
        .for_each(|(i, inv)| *inv = diagonal[i].inverse().unwrap_or_default());
    let graph = local.graph;
    let dt = local.dt;
    nb.springs.clear();
    for i in 0..x.len() {
        for s in graph.of(i) {
            let j = s.other as usize;
            let d = x[i] - x[j];
            let len = d.norm();
            nb.springs
                .push(if len < crate::forces::spring::DEGENERATE_LENGTH {
                    Sym3::default()
                } else {
                    let u = d / len;
                    let (ks, kd) = graph.law(s);
                    let transverse = (1.0 - s.rest / len).max(0.0);
                    Sym3::outer(&u)
                        .scale(ks * (1.0 - transverse) + kd / dt)
                        .plus_identity(ks * transverse)
                });
        }
    }
    nb.pairs.clear();
    nb.pairs.extend(local.detection.pairs.iter().map(|pair| {
        let c = local.pair_contact(pair, x)?;
        let nn = Sym3::outer(&c.n);
        let mut m = nn.scale(c.stiffness);
        let slide = (c.slip - c.n * c.n.dot(&c.slip)).norm();
        let friction = friction_stiffness((pair.mu, c.lambda, c.stiffness), slide, dt);
        if friction > 0.0 {
            m = m.plus(
                &Sym3::default()
                    .plus_identity(friction)
                    .plus(&nn.scale(-friction)),
            );
        }
        Some((c.w, c.len, m))
    }));
}

/// `out = H v`: the diagonal blocks, less each spring's block on its other end, plus each
/// contact's blocks between its particles; pinned rows are zero.
fn multiply(local: &Local<'_>, nb: &NewtonBuffers, v: &[Vec3], out: &mut [Vec3]) {
    let graph = local.graph;
    let detection = local.detection;
    let (pinned, diagonal, springs, pairs) = (&nb.pinned, &nb.diagonal, &nb.springs, &nb.pairs);
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
        for (k, o) in out.iter_mut().enumerate() {
            let i = c * CHUNK + k;
            if pinned[i] {
                *o = Vec3::zeros();
                continue;
            }
            let mut sum = diagonal[i].mul(&v[i]);
            let first = graph.first(i);
            for (e, s) in graph.of(i).iter().enumerate() {
                let j = s.other as usize;
                if !pinned[j] {
                    sum -= springs[first + e].mul(&v[j]);
                }
            }
            for &pk in detection.pair_indices(i) {
                let Some((w, len, m)) = &pairs[pk as usize] else {
                    continue;
                };
                let ids = &detection.pairs[pk as usize].ids;
                let Some(mine) = (0..*len).find(|&a| ids[a] as usize == i).map(|a| w[a]) else {
                    continue;
                };
                for a in 0..*len {
                    let j = ids[a] as usize;
                    if j != i && !pinned[j] && w[a] != 0.0 {
                        sum += m.mul(&v[j]) * (mine * w[a]);
                    }
                }
            }
            *o = sum;
        }
    });
}

/// The fewest conjugate-gradient iterations tried before a factorisation is made.
const FEWEST_ITERATIONS: usize = 16;

/// Solves `H d = f` for the Newton direction by preconditioned conjugate gradients; returns
/// the iterations. A factor of the springs' part (`factor.rs`) preconditions far better than
/// the inverse diagonal blocks, but making it costs as much as hundreds of iterations (a
/// jello lattice's fills in; a cloth's hardly does), and one made at an earlier iterate or
/// step still preconditions well while the system changes slowly. So the solve goes on
/// with what it has (a stale factor, else the diagonal blocks) for as many iterations as
/// a factorisation costs, counted in multiply-adds, and only then factors at the current
/// iterate and finishes with that: never more than twice the cheaper choice's cost (the
/// rent-or-buy rule). Counts, not clocks, decide: the same bits on any machine.
fn solve(
    local: &Local<'_>,
    nb: &mut NewtonBuffers,
    springs: usize,
    cancel: Option<fn() -> bool>,
) -> usize {
    nb.direction.fill(Vec3::zeros());
    let norm = parallel::dot(&nb.force, &nb.force).sqrt();
    if norm == 0.0 {
        return 0;
    }
    let n = nb.force.len();
    let stale = nb.factor.ready && nb.factor.fits(n, springs);
    let (factoring, solving) = nb.factor.costs(local.graph, n, springs);
    // A product with the system: a diagonal block and a block per spring end, 18 each.
    let multiply = 18.0 * (n + nb.springs.len()) as f64;
    let per_iteration = if stale { multiply + solving } else { multiply };
    let budget = ((factoring / per_iteration) as usize).clamp(FEWEST_ITERATIONS, CG_MAX_ITERATIONS);
    let (done, converged) = conjugate_gradients(local, nb, norm, budget, stale, cancel);
    if converged || super::cancelled(cancel) {
        return done;
    }
    {
        let mut pairs = std::mem::take(&mut nb.couplings);
        couplings(local, nb, &mut pairs);
        nb.factor.factor(
            local.graph,
            (&nb.diagonal, &nb.springs),
            (&nb.pinned, &pairs),
            springs,
        );
        nb.couplings = pairs;
    }
    let (more, _) = conjugate_gradients(
        local,
        nb,
        norm,
        CG_MAX_ITERATIONS - done,
        nb.factor.ready,
        cancel,
    );

    done + more
}

/// The contacts' blocks between two particles of one side of the contact (a triangle's
/// corners, an edge's ends), `(i, j, block)` with `i < j`, for the factored preconditioner
/// (which takes those its pattern holds). A side's blocks with its own diagonal blocks
/// are a positive semi-definite whole; the blocks across a contact, which the pattern holds
/// only by chance, are left to the gradients, so that what is factored stays definite.
fn couplings(local: &Local<'_>, nb: &NewtonBuffers, out: &mut Vec<(usize, usize, Sym3)>) {
    use super::vbd::pairs::Sides;
    out.clear();
    for (k, pair) in local.detection.pairs.iter().enumerate() {
        let Some((w, len, m)) = &nb.pairs[k] else {
            continue;
        };
        let side = |a: usize| match pair.sides {
            Sides::PointTriangle(_) => usize::from(a > 0),
            Sides::EdgeEdge => a / 2,
            Sides::Feature(..) => 0,
        };
        for a in 0..*len {
            for b in a + 1..*len {
                let (i, j) = (pair.ids[a] as usize, pair.ids[b] as usize);
                if side(a) == side(b) && w[a] != 0.0 && w[b] != 0.0 && i != j {
                    out.push((i.min(j), i.max(j), m.scale(w[a] * w[b])));
                }
            }
        }
    }
}

/// Conjugate gradients on `H d = f` from the current `d` (its residual recomputed),
/// preconditioned by the factor or the inverse diagonal blocks, for at most `budget`
/// iterations; stops at [`CG_TOLERANCE`] of `norm`. Returns the iterations and whether it
/// got there.
fn conjugate_gradients(
    local: &Local<'_>,
    nb: &mut NewtonBuffers,
    norm: f64,
    budget: usize,
    factored: bool,
    cancel: Option<fn() -> bool>,
) -> (usize, bool) {
    let mut d = std::mem::take(&mut nb.direction);
    let mut r = std::mem::take(&mut nb.r);
    let mut z = std::mem::take(&mut nb.z);
    let mut q = std::mem::take(&mut nb.q);
    let mut s = std::mem::take(&mut nb.s);
    let mut factor = std::mem::take(&mut nb.factor);
    // r = f - H d.
    multiply(local, nb, &d, &mut q);
    parallel::for_each(&mut r, |i, r| *r = nb.force[i] - q[i]);
    let inverse = &nb.inverse;
    let mut precondition = |r: &[Vec3], z: &mut [Vec3]| {
        if factored {
            factor.solve(r, z);
        } else {
            parallel::for_each(z, |i, z| *z = inverse[i].mul(&r[i]));
        }
    };
    let mut iterations = 0;
    let mut converged = parallel::dot(&r, &r).sqrt() <= CG_TOLERANCE * norm;
    if !converged {
        precondition(&r, &mut z);
        s.copy_from_slice(&z);
        let mut delta = parallel::dot(&r, &z);
        while iterations < budget {
            // An interrupt ends the solve with the direction it has (still a descent
            // direction of the preconditioned system), checked every few products.
            if iterations % CANCEL_EVERY == 0 && super::cancelled(cancel) {
                break;
            }
            iterations += 1;
            multiply(local, nb, &s, &mut q);
            let curvature = parallel::dot(&s, &q);
            if curvature.is_nan() || curvature <= 0.0 {
                break;
            }
            let alpha = delta / curvature;
            parallel::axpy(&mut d, alpha, &s);
            parallel::axpy(&mut r, -alpha, &q);
            if parallel::dot(&r, &r).sqrt() <= CG_TOLERANCE * norm {
                converged = true;
                break;
            }
            precondition(&r, &mut z);
            let next = parallel::dot(&r, &z);
            let beta = next / delta;
            delta = next;
            parallel::for_each(&mut s, |i, s| *s = z[i] + *s * beta);
        }
    }
    nb.factor = factor;
    (nb.direction, nb.r, nb.z, nb.q, nb.s) = (d, r, z, q, s);
    (iterations, converged)
}
