//! Vertex block descent (Chen et al., SIGGRAPH 2024) for implicit Euler, with every update
//! held inside a displacement bound so that no surface crosses a collider or another surface
//! (after the offset geometric contact of Chen et al., SIGGRAPH 2025). docs/physics.md §4.1
//! is the contract; in short:
//!
//! * A step minimises the implicit-Euler energy `Σ m/(2dt²) |x - y|² + E(x)` over the
//!   positions `x`, with `y = x₀ + dt v₀ + dt² f_ext / m` and `E` the springs, attachments,
//!   drag and contacts (damping enters as `kd/dt` on the step's displacement).
//! * Iterations visit the particles colour by colour (no spring inside a colour); each takes
//!   one 3×3 Newton step on its own energy, others fixed. Within a colour every update reads
//!   the positions the colour started with, so the result is the same on any thread count.
//! * After the colours, each free body moves as a whole by the Newton step of its
//!   translation (the coarse correction), which Gauss–Seidel alone takes hundreds of
//!   sweeps to make on a stiff sheet.
//! * Every update is clipped to its particle's ball from the last detection (`detect/`),
//!   and kept on the free side of the half-space colliders near it (bounding only the
//!   motion into them, so particles slide along planes).
//! * An iteration that leaves a hundredth of the particles waiting at their bounds ends
//!   with a new detection; fewer wait there until the next step's.
//! * The step stops when its last iteration moved no particle faster than the tolerance of
//!   its [`StopRule`] (a velocity: the move over `dt`), or at its iteration budget. Then
//!   `v = (x - x₀) / dt`.

mod candidates;
mod cells;
pub(in crate::integrator) mod detect;
pub(in crate::integrator) mod graph;
mod lanes;
pub(in crate::integrator) mod local;
pub(in crate::integrator) mod pairs;
mod planes;
pub(crate) mod swept;
mod topology;

use super::{StepReport, StopRule, Workspace};
use crate::integrator::Sym3;
use crate::model::Model;
use crate::particles::{Particles, Vec3};
use detect::{Centres, Detection};
use graph::Graph;
use lanes::{LANES, Lanes};
use local::{Block, Gaps, Local};
use rayon::prelude::*;

/// Block descent is implicit Euler: stable for every step.
pub(in crate::integrator) const STABILITY_RADIUS: f64 = f64::INFINITY;
/// The share of the free particles that must wait at their bounds before an iteration
/// detects again (besides the detection at every step's start).
const DETECT_SHARE: f64 = 0.01;
/// The spectral radius assumed by the Chebyshev acceleration (0: none).
const CHEBYSHEV: f64 = 0.9;
/// Particles per parallel chunk of a colour (a whole number of the lanes' blocks).
const CHUNK: usize = 256;
const _: () = assert!(CHUNK.is_multiple_of(LANES));
/// Up to this many chunks (a 32² cloth), the coarse step sums a body's chunks in order on
/// the calling thread: waking the pool at every iteration cost more than it saved (on
/// cloth-table the coarse step took 0.27 s of 3 s in parallel, 0.18 s so; a 36² cloth, six
/// chunks, takes the same either way). The chunks and their order, so the bits, are the same.
const SERIAL_CHUNKS: usize = 4;

/// Buffers of the block-descent step, kept between steps.
#[derive(Clone, Debug, Default)]
pub(crate) struct VbdBuffers {
    pub(in crate::integrator) graph: Graph,
    /// The colours' springs laid out for the sweep's lanes.
    lanes: Lanes,
    pub(in crate::integrator) detection: Detection,
    /// Inertial targets.
    pub(in crate::integrator) target: Vec<Vec3>,
    /// Per particle: `m v + dt f_ext`, its momentum after the step were it free.
    pub(in crate::integrator) momentum: Vec<Vec3>,
    /// Positions at the last detection.
    pub(in crate::integrator) detected: Vec<Vec3>,
    /// One colour's new positions and whether each was clipped.
    next: Vec<(Vec3, bool)>,
    /// Velocities at the start of the last step (for the first guess).
    previous: Vec<Vec3>,
    /// The last two iterates (for the acceleration).
    old: Vec<Vec3>,
    older: Vec<Vec3>,
    /// Per chunk of a body: its particles' forces and translation stiffness, summed.
    parts: Vec<(Vec3, Sym3)>,
    /// Iterations and detections of the last step.
    pub(crate) iterations: usize,
    pub(crate) detections: usize,
    /// Parts the last step was taken in (more than one only with a moving collider).
    pub(crate) step_parts: u32,
    /// Whether the last step ended at its iteration budget without meeting its stopping rule.
    pub(crate) capped: bool,
    /// The last step's residual: the largest force left on a free particle at the end of
    /// the step, over its weight (docs/physics.md §4.1), when [`VbdBuffers::evidence`] asks
    /// for it (it costs a sweep).
    pub(crate) residual: f64,
    /// Whether to measure the residual.
    pub(crate) evidence: bool,
    /// The largest move of the last step's last iteration over the step, m/s.
    pub(crate) last_speed: f64,
    /// Where the steps' time went, summed.
    pub(crate) times: crate::integrator::SolveTimes,
}

impl VbdBuffers {
    /// The pairs self-contact skips under block descent and Newton's step.
    pub(crate) fn exclusion(&self) -> &crate::contact::exclusion::Exclusion {
        self.detection.exclusion()
    }
}

pub(in crate::integrator) fn step(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
) -> StepReport {
    let mut clock = crate::integrator::Lap::start();
    let rule = ws.stop.unwrap_or(StopRule::VBD);
    let cancel = ws.cancel;
    let kernel = ws.kernel.unwrap_or_else(crate::Kernel::detect);
    let n = p.len();
    prepare(model, p, (t, dt), ws, &mut clock);
    let b = &mut ws.vbd;
    recolour(&mut b.graph, &b.detection, p);
    b.times.detection += clock.lap();
    let g = model.gravity.norm();
    let free = (0..n).filter(|&i| !p.is_pinned(i)).count();
    // Detect again when this many particles wait at their bounds (Chen et al. 2025 detect
    // again at 1 % of the vertices): fewer wait there until the next step.
    let enough = ((DETECT_SHARE * free as f64).ceil() as usize).max(1);
    let mut omega = 1.0;
    let mut since_detection = 0;
    let start = &ws.x0;
    let mut iterations = 0;
    let mut converged = false;
    let (mut last_move, mut before_last) = (0.0, 0.0);
    while iterations < rule.iterations && !super::cancelled(cancel) {
        iterations += 1;
        let mut largest = 0.0_f64;
        let mut held = 0;
        let local = Local {
            model,
            graph: &b.graph,
            detection: &b.detection,
            mass: &p.mass,
            start,
            target: &b.target,
            dt,
        };
        b.lanes.follow(&b.graph);
        for (c, colour) in b.graph.colours.iter().enumerate() {
            let (x, detected, detection, lanes) = (&p.x, &b.detected, &b.detection, &b.lanes);
            b.next.resize(colour.len(), (Vec3::zeros(), false));
            // `first`: the lanes' block the chunk starts at.
            let update = |first: usize, ids: &[u32], out: &mut [(Vec3, bool)]| {
                let mut gaps = Gaps::default();
                let mut blocks = [Block::default(); LANES];
                for (k, (ids, out)) in ids.chunks(LANES).zip(out.chunks_mut(LANES)).enumerate() {
                    lanes.sum(kernel, (&local, x), (c, first + k, ids), &mut blocks);
                    for ((&i, o), block) in ids.iter().zip(out).zip(blocks) {
                        let i = i as usize;
                        *o = clip(detection, detected, i, local.update(i, x, block, &mut gaps));
                    }
                }
            };
            if colour.len() <= CHUNK {
                update(0, colour, &mut b.next);
            } else {
                colour
                    .par_chunks(CHUNK)
                    .zip(b.next.par_chunks_mut(CHUNK))
                    .enumerate()
                    .for_each(|(k, (ids, out))| update(k * (CHUNK / LANES), ids, out));
            }
            for (&i, &(xi, c)) in colour.iter().zip(&b.next) {
                let i = i as usize;
                largest = largest.max((xi - p.x[i]).norm());
                held += usize::from(c);
                p.x[i] = xi;
            }
        }
        b.times.sweeps += clock.lap();
        let (moved, c) = translate_bodies(&local, &b.detected, &mut b.parts, &mut p.x);
        largest = largest.max(moved);
        held += c;
        b.times.coarse += clock.lap();
        // The anchors' rule (IPC's): the step is solved when its last update moved no
        // particle faster than the tolerance over the step, and none waits at its bound.
        // Gauss–Seidel on a stiff or volumetric body crawls towards its solution by small
        // updates that shrink slowly; what is left to go is about the update over one less
        // its contraction `r` (the larger of the last two updates' ratios), and that is
        // what the tolerance bounds.
        let ratio = |now: f64, before: f64| {
            if before > 0.0 {
                (now / before).min(1.0)
            } else {
                0.0
            }
        };
        let contraction = ratio(largest, last_move).max(ratio(last_move, before_last));
        let settled = largest <= (1.0 - contraction) * rule.tolerance * dt;
        before_last = last_move;
        last_move = largest;
        if settled && held == 0 {
            converged = true;
            break;
        }
        // Chebyshev semi-iterative acceleration (Wang 2015, as Chen et al. 2024 use it),
        // restarted at each detection; each result clipped again.
        since_detection += 1;
        if since_detection >= 2 && CHEBYSHEV > 0.0 && iterations < rule.iterations {
            omega = if since_detection == 2 {
                2.0 / (2.0 - CHEBYSHEV * CHEBYSHEV)
            } else {
                4.0 / (4.0 - CHEBYSHEV * CHEBYSHEV * omega)
            };
            for i in 0..n {
                // Contacts are not smooth: particles that may touch are not extrapolated.
                if !p.is_pinned(i) && !b.detection.may_touch(i) {
                    let to = b.older[i] + (p.x[i] - b.older[i]) * omega;
                    p.x[i] = clip(&b.detection, &b.detected, i, to).0;
                }
            }
        }
        std::mem::swap(&mut b.older, &mut b.old);
        b.old.copy_from_slice(&p.x);
        b.times.acceleration += clock.lap();
        // Detect again when enough particles wait at their bounds, or when they are all
        // that is left to move.
        if (held >= enough || (settled && held > 0)) && iterations < rule.iterations {
            b.detection.detect(
                model,
                p,
                &b.graph,
                (&p.x, &b.target),
                (dt, Centres::Shifted),
            );
            recolour(&mut b.graph, &b.detection, p);
            b.detected.copy_from_slice(&p.x);
            b.detections += 1;
            since_detection = 0;
            b.older.copy_from_slice(&p.x);
            b.times.detection += clock.lap();
        }
    }
    if b.evidence {
        b.residual = residual(
            &Local {
                model,
                graph: &b.graph,
                detection: &b.detection,
                mass: &p.mass,
                start,
                target: &b.target,
                dt,
            },
            p,
            g,
        );
    }
    finish(b, (iterations, converged, last_move), p, start, dt);
    keep_momentum(model, p, start, &b.momentum, dt);
    StepReport::SAVED
}

/// Records a large step's counts (block descent's or Newton's) and sets the free
/// particles' velocities `(x - x⁰) / dt`.
pub(in crate::integrator) fn finish(
    b: &mut VbdBuffers,
    (iterations, converged, last_move): (usize, bool, f64),
    p: &mut Particles,
    start: &[Vec3],
    dt: f64,
) {
    b.iterations = iterations;
    b.step_parts = 1;
    b.capped = !converged;
    b.last_speed = last_move / dt;
    for (i, (v, (x, s))) in p.v.iter_mut().zip(p.x.iter().zip(start)).enumerate() {
        if p.inv_mass[i] != 0.0 {
            *v = (x - s) / dt;
        }
    }
}

/// What block descent and Newton's step share before they iterate (docs/physics.md §4.1):
/// the start positions, the inertial targets and free momenta, the detection at the step's
/// start, the keyed pins put at their ends, and the first guess clipped to the bounds.
pub(in crate::integrator) fn prepare(
    model: &Model,
    p: &mut Particles,
    (t, dt): (f64, f64),
    ws: &mut Workspace,
    clock: &mut crate::integrator::Lap,
) {
    let n = p.len();
    ws.x0.copy_from_slice(&p.x);
    let air = ws
        .air
        .evaluate(model.air.as_ref(), &model.aero, &p.x, &p.v, t);
    let b = &mut ws.vbd;
    if !b.graph.fits(n, model.springs.len()) {
        b.graph = Graph::new(model, p);
    }
    // Inertial targets `x + dt v + dt² f_ext/m`, and each particle's momentum after the
    // step were it free, `m v + dt f_ext`.
    let external = |i: usize| {
        let mut f = model.gravity * p.mass[i];
        if let Some(field) = &model.field {
            f += field.sample(&p.x[i]);
        }
        if let Some(a) = air.get(i) {
            f += a;
        }
        f
    };
    b.target.clear();
    b.momentum.clear();
    for i in 0..n {
        let f = external(i);
        b.momentum.push(p.v[i] * p.mass[i] + f * dt);
        b.target.push(if p.is_pinned(i) {
            p.x[i] + p.v[i] * dt
        } else {
            p.x[i] + p.v[i] * dt + f * (dt * dt / p.mass[i])
        });
    }
    // The targets are the step's, not the solve's: their time is the rest's.
    let _ = clock.lap();
    b.detection.detect(
        model,
        p,
        &b.graph,
        (&p.x, &b.target),
        (dt, Centres::Shifted),
    );
    // A keyframed pin moves at its velocity over the step (docs/physics.md §1.2): implicit
    // Euler solves the free particles against where it ends, so its springs pull them along
    // within the step, and it keeps that velocity (a still pin's target is where it is).
    // The detection, at the step's start, counted that move in the bounds.
    for ((x, target), inv_mass) in p.x.iter_mut().zip(&b.target).zip(&p.inv_mass) {
        if *inv_mass == 0.0 {
            *x = *target;
        }
    }
    b.detected.clear();
    b.detected.extend_from_slice(&p.x);
    b.detections = 1;
    // The first guess (after Chen et al. 2024's adaptive one): the inertial motion with as
    // much of gravity as the particle showed last step (none for a cloth at rest on a table,
    // all of it in free fall), clipped to the bounds of the step's detection.
    let g = model.gravity.norm();
    let fresh = b.previous.len() != n;
    for i in 0..n {
        if p.is_pinned(i) {
            continue;
        }
        let share = if fresh || g == 0.0 {
            1.0
        } else {
            let a = (p.v[i] - b.previous[i]) / dt;
            (a.dot(&model.gravity) / (g * g)).clamp(0.0, 1.0)
        };
        let guess = p.x[i] + p.v[i] * dt + model.gravity * (share * dt * dt);
        p.x[i] = clip(&b.detection, &b.detected, i, guess).0;
    }
    b.previous.clear();
    b.previous.extend_from_slice(&p.v);
    b.older.clear();
    b.older.extend_from_slice(&p.x);
    b.old.clear();
    b.old.extend_from_slice(&p.x);
}

/// The coarse correction (a two-level scheme's coarsest level, after Tamstorf et al. 2015):
/// each free body moves as a whole by the Newton step of its translation, `Δ = H⁻¹ F`
/// with `F` the sum of its particles' forces and `H` of their Hessians, both without the
/// springs' terms (which cancel for a translation), every particle clipped to its bounds. Gauss–Seidel
/// moves a stiff sheet as a whole by about `m/dt² / Σ ks` of the way per sweep; this moves
/// it all the way in one. Sums in fixed chunks, in order: the same bits on any thread count.
/// Returns the largest move and how many particles were clipped.
fn translate_bodies(
    local: &Local<'_>,
    detected: &[Vec3],
    parts: &mut Vec<(Vec3, Sym3)>,
    x: &mut [Vec3],
) -> (f64, usize) {
    let (mut largest, mut clipped) = (0.0f64, 0);
    let graph = local.graph;
    for (k, body) in graph.free_bodies.iter().enumerate() {
        // A body touching another is left to the sweeps (see `mark_touching_bodies`).
        if local.detection.touches_another[k] {
            continue;
        }
        let chunks = body.len().div_ceil(CHUNK);
        parts.clear();
        parts.resize(chunks, (Vec3::zeros(), Sym3::default()));
        let sum = |ids: &[u32], out: &mut (Vec3, Sym3)| {
            for &i in ids {
                let (f, h) = local.translation(i as usize, x);
                out.0 += f;
                out.1 = out.1.plus(&h);
            }
        };
        if chunks <= SERIAL_CHUNKS {
            for (ids, out) in body.chunks(CHUNK).zip(parts.iter_mut()) {
                sum(ids, out);
            }
        } else {
            body.par_chunks(CHUNK)
                .zip(parts.par_iter_mut())
                .for_each(|(ids, out)| sum(ids, out));
        }
        let (f, h) = parts
            .iter()
            .fold((Vec3::zeros(), Sym3::default()), |(f, h), (pf, ph)| {
                (f + pf, h.plus(ph))
            });
        let Some(d) = h
            .inverse()
            .map(|inv| inv.mul(&f))
            .filter(|d| d.iter().all(|c| c.is_finite()))
        else {
            continue;
        };
        for &i in body {
            let i = i as usize;
            let (to, c) = clip(local.detection, detected, i, x[i] + d);
            largest = largest.max((to - x[i]).norm());
            clipped += usize::from(c);
            x[i] = to;
        }
    }
    (largest, clipped)
}

/// The largest force left on a free particle, over its weight `m a` with `a` gravity's
/// magnitude `g` (1 m/s² where there is none): the residual of the implicit-Euler
/// equations at the step's end. A maximum, so the same on any thread count.
fn residual(local: &Local<'_>, p: &Particles, g: f64) -> f64 {
    let a = if g > 0.0 { g } else { 1.0 };
    (0..p.len())
        .into_par_iter()
        .with_min_len(CHUNK)
        .filter(|&i| !p.is_pinned(i))
        .map(|i| local.force(i, &p.x).norm() / (p.mass[i] * a))
        .reduce(|| 0.0, f64::max)
}

/// Springs and contacts between the bodies' own particles are internal forces, so implicit
/// Euler's step changes the momentum by `dt Σ f_ext` exactly (`momentum`: each particle's
/// `m v + dt f_ext`); the iterations stop short of that. When nothing else acts (no
/// collider, pin, attachment or drag), the leftover is spread as one velocity, which moves
/// no particle relative to another (no crossing), and momentum is kept to round-off, as
/// the other integrators keep it.
pub(in crate::integrator) fn keep_momentum(
    model: &Model,
    p: &mut Particles,
    start: &[Vec3],
    momentum: &[Vec3],
    dt: f64,
) {
    let closed = model.colliders.is_empty()
        && model.attachments.is_empty()
        && !model.has_drag()
        && (0..p.len()).all(|i| !p.is_pinned(i));
    if !closed {
        return;
    }
    let mut want = Vec3::zeros();
    let mut have = Vec3::zeros();
    let mut mass = 0.0;
    for ((m, v), target) in p.mass.iter().zip(&p.v).zip(momentum) {
        want += target;
        have += v * *m;
        mass += m;
    }
    let dv = (want - have) / mass;
    for ((v, x), s) in p.v.iter_mut().zip(&mut p.x).zip(start) {
        *v += dv;
        *x = s + *v * dt;
    }
}

/// Colours the particles anew when the detection found pairs, so that no two particles of
/// a pair move in one colour (they would both close the same gap and overshoot it); the
/// springs' colouring otherwise, kept from the last time.
fn recolour(graph: &mut Graph, detection: &Detection, p: &Particles) {
    if detection.has_pairs() || graph.coloured_with_contacts {
        graph.colour(p, |i, f| detection.partners(i, f));
        graph.coloured_with_contacts = detection.has_pairs();
    }
}

/// `to` clipped to particle `i`'s ball, and whether it had to be.
#[inline]
pub(in crate::integrator) fn clip(
    detection: &Detection,
    detected: &[Vec3],
    i: usize,
    to: Vec3,
) -> (Vec3, bool) {
    let centre = if detection.shifted[i] {
        detected[i] + detection.shift
    } else {
        detected[i]
    };
    let r = detection.bound[i];
    let off = to - centre;
    let len = off.norm();
    let (mut x, mut clipped) = if len <= r {
        (to, false)
    } else {
        (centre + off * (r / len), true)
    };
    // Each half-space keeps `(1 - γ)` of the particle's gap to it. A point that goes too
    // deep is lifted back along the plane's normal, keeping its sliding, when that stays in
    // the ball and keeps every half-space; otherwise it is taken back along the segment
    // from the centre, which keeps them all.
    let halves = detection.halves.of(i);
    let floor = |d: f64| (1.0 - detect::GAMMA_COLLIDER) * d;
    let depth =
        |y: &Vec3, &(point, normal, d): &(Vec3, Vec3, f64)| floor(d) - normal.dot(&(y - point));
    if halves.iter().any(|h| depth(&x, h) > 0.0) {
        clipped = true;
        let mut lifted = x;
        for h in halves.iter() {
            lifted += h.1 * depth(&lifted, h).max(0.0);
        }
        if (lifted - centre).norm() <= r && halves.iter().all(|h| depth(&lifted, h) <= 0.0) {
            x = lifted;
        } else {
            for h in halves.iter() {
                let (below, from) = (depth(&x, h), depth(&centre, h));
                if below > 0.0 {
                    let t = if below > from {
                        (-from / (below - from)).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    x = centre + (x - centre) * t;
                }
            }
        }
    }
    (x, clipped)
}
