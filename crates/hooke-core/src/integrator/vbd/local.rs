//! One particle's block update: a Newton step on its share of the implicit-Euler energy,
//! the others held where they are (docs/physics.md §4.1).

use super::detect::{Detection, collider_law};
use super::graph::Graph;
use super::pairs::{Pair, Sides, stencil};
use super::planes::Plane;
use crate::collider::response::Response;
use crate::integrator::Sym3;
use crate::model::Model;
use crate::particles::Vec3;

/// Tangential speeds below this are treated as sticking (friction's smoothing), m/s.
pub(crate) const STATIC_SPEED: f64 = 1e-3;
/// A contact whose gap is within this share of its thickness beyond the thickness adds its
/// stiffness to the Hessian but no force: without it a particle resting on a contact would
/// alternate between the step that ignores the contact (a gravity-sized fall into it) and
/// the one that pushes it back out.
pub(crate) const BAND: f64 = 0.25;
/// Gaps shorter than this have no direction of their own, metres.
const EPS: f64 = 1e-12;

/// A contact pair at some positions (see [`Local::pair_contact`]).
#[derive(Clone, Copy, Debug)]
pub(in crate::integrator) struct PairContact {
    /// Weights on the pair's particles (`len` of them) and the unit normal of its gap.
    pub(in crate::integrator) w: [f64; 4],
    pub(in crate::integrator) len: usize,
    pub(in crate::integrator) n: Vec3,
    /// The gap's length and the normal force of the contact law there (negative in the
    /// band beyond the thickness: stiffness only).
    pub(in crate::integrator) d: f64,
    pub(in crate::integrator) lambda: f64,
    /// The law's normal stiffness there (the barrier's below half the thickness).
    pub(in crate::integrator) stiffness: f64,
    /// The stencil's displacement over the step (friction reads its tangential part).
    pub(in crate::integrator) slip: Vec3,
}

/// The tangential stiffness of a contact with Coulomb coefficient `mu` (infinite: stick),
/// normal force `lambda` and normal stiffness `k`, whose point slid `slide` over the step:
/// Coulomb's `μ λ / |s_t|`, smoothed below [`STATIC_SPEED`]; zero in the band.
pub(in crate::integrator) fn friction_stiffness(
    (mu, lambda, k): (f64, f64, f64),
    slide: f64,
    dt: f64,
) -> f64 {
    if lambda <= 0.0 || mu == 0.0 {
        0.0
    } else if mu.is_infinite() {
        k
    } else {
        mu * lambda / slide.max(STATIC_SPEED * dt)
    }
}

/// What every particle's update reads: the step's data and the last detection.
pub(in crate::integrator) struct Local<'a> {
    pub(in crate::integrator) model: &'a Model,
    pub(in crate::integrator) graph: &'a Graph,
    pub(in crate::integrator) detection: &'a Detection,
    pub(in crate::integrator) mass: &'a [f64],
    /// Positions at the step's start.
    pub(in crate::integrator) start: &'a [Vec3],
    /// Inertial targets `x + dt v + dt² f_ext / m`.
    pub(in crate::integrator) target: &'a [Vec3],
    pub(in crate::integrator) dt: f64,
}

/// A gradient and Hessian being summed: `f` is minus the gradient (a force).
#[derive(Clone, Copy, Debug, Default)]
pub(in crate::integrator) struct Block {
    pub(in crate::integrator) f: Vec3,
    pub(in crate::integrator) h: Sym3,
}

/// Where a sum puts its contacts' gaps as `(d, g)`: the step `s` changes gap `d` by about
/// `g · s`. The update bounds each gap's closing; the other sums need none, and take `()`.
trait GapSink {
    fn push(&mut self, gap: (f64, Vec3));
}

impl GapSink for () {
    #[inline]
    fn push(&mut self, _: (f64, Vec3)) {}
}

/// An update's contact gaps, kept by the caller between particles: a particle rarely has
/// more than a few contacts, and clearing a list costs nothing where a fresh one per
/// particle and iteration cost a twentieth of the sweep (it was zeroed and copied).
#[derive(Debug, Default)]
pub(in crate::integrator) struct Gaps(Vec<(f64, Vec3)>);

impl GapSink for Gaps {
    #[inline]
    fn push(&mut self, gap: (f64, Vec3)) {
        self.0.push(gap);
    }
}

impl Block {
    /// A contact's normal force `λ n` with stiffness `k`, and its friction: Coulomb with
    /// coefficient `mu` on the tangential part of `slip` (the contact point's displacement
    /// over the step), smoothed below [`STATIC_SPEED`]; an infinite `mu` holds it with the
    /// stiffness `k`. `w` is this particle's weight in the contact.
    #[allow(clippy::too_many_arguments)]
    fn contact(
        &mut self,
        (n, lambda, k): (Vec3, f64, f64),
        gap: Option<f64>,
        mu: f64,
        slip: Vec3,
        w: f64,
        dt: f64,
        gaps: &mut impl GapSink,
    ) {
        let nn = Sym3::outer(&n);
        self.h = self.h.plus(&nn.scale(k * w * w));
        if let Some(d) = gap {
            gaps.push((d, n * w));
        }
        if lambda <= 0.0 {
            // In the band: stiffness only.
            return;
        }
        self.f += n * (lambda * w);
        if mu == 0.0 {
            return;
        }
        let tangent = Sym3::default().plus_identity(1.0).plus(&nn.scale(-1.0));
        let slide = slip - n * n.dot(&slip);
        let c = friction_stiffness((mu, lambda, k), slide.norm(), dt);
        self.f -= slide * (c * w);
        self.h = self.h.plus(&tangent.scale(c * w * w));
    }
}

/// The energy of the contact law [`normal_law`] at gap `d` (zero at and beyond `h`): the
/// spring's `k (h - d)²/2` down to `h/2`, then the barrier's `c ln(h / (2d))` on top of it,
/// `c = k h²/4`, so that minus its derivative is the law's force.
pub(in crate::integrator) fn normal_energy(d: f64, h: f64, k: f64) -> f64 {
    let tau = 0.5 * h;
    if d >= h {
        0.0
    } else if d >= tau {
        0.5 * k * (h - d) * (h - d)
    } else {
        let d = d.max(1e-6 * h);
        let c = k * (h - tau) * tau;
        0.5 * k * (h - tau) * (h - tau) + c * (tau / d).ln()
    }
}

/// A friction's energy: Coulomb's `μ λ |s|`, smoothed below `ε` (Huber's), whose minus
/// gradient is the friction force of [`friction_stiffness`]; a stick's spring `k |s|²/2`.
pub(in crate::integrator) fn friction_energy(
    (mu, lambda, k): (f64, f64, f64),
    slide: f64,
    dt: f64,
) -> f64 {
    if lambda <= 0.0 || mu == 0.0 {
        0.0
    } else if mu.is_infinite() {
        0.5 * k * slide * slide
    } else {
        let eps = STATIC_SPEED * dt;
        let s = slide.abs();
        mu * lambda
            * if s < eps {
                0.5 * s * s / eps
            } else {
                s - 0.5 * eps
            }
    }
}

/// The normal force and stiffness of a contact whose gap `d` is kept at `h` with stiffness
/// `k`, along `n`: the spring `k (h - d)` down to `h/2`, below it a logarithmic barrier
/// joined with the same force and stiffness, `k h²/(4 d)`, which no finite load closes
/// (after the two-stage energy of Chen et al. 2025). Beyond `h` the force is negative (the
/// band: stiffness only).
fn normal_law(d: f64, h: f64, k: f64, n: Vec3) -> (Vec3, f64, f64) {
    let tau = 0.5 * h;
    if d >= tau {
        (n, k * (h - d), k)
    } else {
        let d = d.max(1e-6 * h);
        let c = k * (h - tau) * tau;
        (n, c / d, c / (d * d))
    }
}

impl Local<'_> {
    /// Particle `i`'s position after one Newton step on its local energy at positions `x`,
    /// given its block's inertia, drag and springs (the sweep sums those eight particles at
    /// a time, `lanes/`); `gaps` is the caller's buffer, cleared here.
    pub(in crate::integrator) fn update(
        &self,
        i: usize,
        x: &[Vec3],
        mut b: Block,
        gaps: &mut Gaps,
    ) -> Vec3 {
        gaps.0.clear();
        self.others(i, x, &mut b, gaps);
        let xi = x[i];
        let inertia = self.mass[i] / (self.dt * self.dt);
        let step =
            b.h.inverse()
                .map(|inv| inv.mul(&b.f))
                .filter(|s| s.iter().all(|c| c.is_finite()))
                .unwrap_or(b.f / inertia);
        // No contact gap closes by more than half in one update: a Newton step on the
        // barrier overshoots under a large load, and the bound would then only halve the
        // gap again and again.
        let scale = gaps
            .0
            .iter()
            .map(|&(d, g)| {
                let closing = -g.dot(&step);
                if closing > 0.5 * d {
                    0.5 * d / closing
                } else {
                    1.0
                }
            })
            .fold(1.0, f64::min);
        xi + step * scale.max(0.0)
    }

    /// The force left on particle `i` at positions `x`: minus the gradient of the step's
    /// energy with respect to its position (contacts in their band count no force, as in
    /// the update). Zero at the solution of the implicit-Euler equations.
    pub(in crate::integrator) fn force(&self, i: usize, x: &[Vec3]) -> Vec3 {
        self.row(i, x).0
    }

    /// Particle `i`'s force (minus the gradient of its terms of the step's energy) and its
    /// diagonal Hessian block at positions `x`: a Newton system's row of it.
    pub(in crate::integrator) fn row(&self, i: usize, x: &[Vec3]) -> (Vec3, Sym3) {
        let mut b = self.springs(i, x);
        self.others(i, x, &mut b, &mut ());
        (b.f, b.h)
    }

    /// The step's energy at positions `x` (docs/physics.md §4.2): inertia, springs and
    /// their damping, drag, attachments, the colliders' contacts and the pairs', with
    /// friction (Huber-smoothed Coulomb). The direction of a spring's damping and the
    /// normal force friction is scaled by are taken at `base` (lagged, as IPC lags its
    /// friction), so that minus its gradient at `x = base` is exactly every particle's
    /// [`Local::row`] force and a line search from `base` measures what the forces ask.
    /// Sums run over fixed chunks added in order, so any thread count gives the same bits.
    /// `parts` holds the chunks' partial sums (kept by the caller, so that a line search
    /// allocates nothing).
    pub(in crate::integrator) fn energy(
        &self,
        x: &[Vec3],
        base: &[Vec3],
        pinned: &[bool],
        parts: &mut Vec<f64>,
    ) -> f64 {
        use rayon::prelude::*;
        const CHUNK: usize = 1024;
        let dt = self.dt;
        let model = self.model;
        let mut chunked = |n: usize, f: &(dyn Fn(usize) -> f64 + Sync)| -> f64 {
            parts.clear();
            parts.resize(n.div_ceil(CHUNK), 0.0);
            parts.par_iter_mut().enumerate().for_each(|(c, part)| {
                *part = (c * CHUNK..((c + 1) * CHUNK).min(n)).map(f).sum::<f64>();
            });
            parts.iter().sum()
        };
        let particle = |i: usize| {
            if pinned[i] {
                return 0.0;
            }
            let xi = x[i];
            let moved = xi - self.start[i];
            let mut e = 0.5 * self.mass[i] / (dt * dt) * (xi - self.target[i]).norm_squared();
            if model.has_drag() {
                e += 0.5 * model.drag_on(self.mass[i]) / dt * moved.norm_squared();
            }
            for a in model.attachments.iter().filter(|a| a.particle == i) {
                e += 0.5 * a.ks * (xi - a.target).norm_squared()
                    + 0.5 * a.kd / dt * moved.norm_squared();
            }
            e + self.collider_energy(i, (&xi, &base[i]), moved)
        };
        let springs = |k: usize| {
            let s = &model.springs[k];
            let (i, j) = (s.i as usize, s.j as usize);
            let d = x[i] - x[j];
            let len = d.norm();
            if len < crate::forces::spring::DEGENERATE_LENGTH {
                return 0.0;
            }
            let lagged = base[i] - base[j];
            let along = lagged.try_normalize(0.0).unwrap_or(d / len);
            let rate = ((x[i] - self.start[i]) - (x[j] - self.start[j])).dot(&along);
            0.5 * s.ks * (len - s.rest) * (len - s.rest) + 0.5 * s.kd / dt * rate * rate
        };
        let pairs = |k: usize| {
            let pair = &self.detection.pairs[k];
            let Some(c) = self.pair_contact(pair, x) else {
                return 0.0;
            };
            let lagged = self.pair_contact(pair, base).unwrap_or(c);
            let n = lagged.n;
            let slide = (c.slip - n * n.dot(&c.slip)).norm();
            normal_energy(c.d, pair.h, pair.k)
                + friction_energy((pair.mu, lagged.lambda, lagged.stiffness), slide, dt)
        };
        chunked(x.len(), &particle)
            + chunked(model.springs.len(), &springs)
            + chunked(self.detection.pairs.len(), &pairs)
    }

    /// Particle `i`'s energy against the colliders it touches, at `xi` with its friction's
    /// normal force lagged at `base` (see [`Local::energy`]).
    fn collider_energy(&self, i: usize, (xi, base): (&Vec3, &Vec3), moved: Vec3) -> f64 {
        let touches = self.detection.touches.of(i);
        let dt = self.dt;
        let mut e = 0.0;
        for plane in touches {
            let n = plane.normal;
            let d = n.dot(&(xi - plane.point));
            let slot = &self.model.colliders[plane.collider as usize];
            let margin = self.detection.keeps(self.model, i, &slot.response);
            let depth = margin - d;
            let moved = if slot.shape.is_moving() {
                moved - slot.shape.velocity(&plane.point) * dt
            } else {
                moved
            };
            match slot.response {
                Response::Penalty { kc, dc } => {
                    if depth > 0.0 {
                        e += 0.5 * kc * depth * depth;
                    }
                    if self.penalty_damps(i, plane) {
                        let rate = moved.dot(&n);
                        e += 0.5 * dc / dt * rate * rate;
                    }
                }
                ref response => {
                    let (k, mu) = collider_law(response, self.detection.scale[i]);
                    let d0 = n.dot(&(base - plane.point));
                    let (normal, lambda, stiffness) = if margin > 0.0 {
                        let (_, lambda, stiffness) = normal_law(d0, margin, k, n);
                        (normal_energy(d, margin, k), lambda, stiffness)
                    } else if depth > 0.0 {
                        let depth0 = (margin - d0).max(0.0);
                        (0.5 * k * depth * depth, k * depth0, k)
                    } else {
                        (0.0, k * (margin - d0).max(0.0), k)
                    };
                    let slide = (moved - n * n.dot(&moved)).norm();
                    e += normal + friction_energy((mu, lambda, stiffness), slide, dt);
                }
            }
        }
        e
    }

    /// What particle `i` adds to its body's translation at positions `x`: its force and
    /// Hessian block without the springs' terms, which cancel over a body moved as a whole
    /// (and so are not computed).
    pub(in crate::integrator) fn translation(&self, i: usize, x: &[Vec3]) -> (Vec3, Sym3) {
        let mut b = self.inertia(i, x);
        self.others(i, x, &mut b, &mut ());
        (b.f, b.h)
    }

    /// Particle `i`'s inertia and drag at positions `x`: where its block's sum starts.
    fn inertia(&self, i: usize, x: &[Vec3]) -> Block {
        let dt = self.dt;
        let inertia = self.mass[i] / (dt * dt);
        let xi = x[i];
        let mut b = Block {
            f: (self.target[i] - xi) * inertia,
            h: Sym3::default().plus_identity(inertia),
        };
        let model = self.model;
        if model.has_drag() {
            let moved = xi - self.start[i];
            let drag = model.drag_on(self.mass[i]) / dt;
            b.f -= moved * drag;
            b.h = b.h.plus_identity(drag);
        }
        b
    }

    /// Particle `i`'s inertia, drag and springs at positions `x`, one particle at a time
    /// (`lanes/` sums the same terms in the same order eight particles at a time).
    pub(super) fn springs(&self, i: usize, x: &[Vec3]) -> Block {
        let dt = self.dt;
        let xi = x[i];
        let moved = xi - self.start[i];
        let mut b = self.inertia(i, x);
        for nb in self.graph.of(i) {
            let (ks, kd) = self.graph.law(nb);
            let j = nb.other as usize;
            let d = xi - x[j];
            let len = d.norm();
            if len < crate::forces::spring::DEGENERATE_LENGTH {
                continue;
            }
            let u = d / len;
            let rate = (moved - (x[j] - self.start[j])).dot(&u) / dt;
            b.f -= u * (ks * (len - nb.rest) + kd * rate);
            // The transverse term is dropped for compressed springs, which keeps the block
            // positive definite (as the implicit integrator's, Choi & Ko 2002).
            let transverse = (1.0 - nb.rest / len).max(0.0);
            b.h = b.h.plus(
                &Sym3::outer(&u)
                    .scale(ks * (1.0 - transverse) + kd / dt)
                    .plus_identity(ks * transverse),
            );
        }
        b
    }

    /// Adds particle `i`'s attachments and contacts at positions `x` to its block `b`, their
    /// gaps to `gaps`.
    fn others(&self, i: usize, x: &[Vec3], b: &mut Block, gaps: &mut impl GapSink) {
        let xi = x[i];
        let moved = xi - self.start[i];
        let dt = self.dt;
        for a in self.model.attachments.iter().filter(|a| a.particle == i) {
            b.f -= (xi - a.target) * a.ks + moved * (a.kd / dt);
            b.h = b.h.plus_identity(a.ks + a.kd / dt);
        }
        self.colliders(i, &xi, moved, b, gaps);
        self.pairs(i, x, b, gaps);
    }

    fn colliders(&self, i: usize, xi: &Vec3, moved: Vec3, b: &mut Block, gaps: &mut impl GapSink) {
        let touches = self.detection.touches.of(i);
        if touches.is_empty() {
            return;
        }
        let dt = self.dt;
        for plane in touches {
            let n = plane.normal;
            let d = n.dot(&(xi - plane.point));
            let slot = &self.model.colliders[plane.collider as usize];
            let margin = self.detection.keeps(self.model, i, &slot.response);
            let depth = margin - d;
            let penalty = matches!(slot.response, Response::Penalty { .. });
            if d >= margin * (1.0 + BAND) && !penalty {
                continue;
            }
            // Damping and friction read the motion relative to a moving collider's surface.
            let moved = if slot.shape.is_moving() {
                moved - slot.shape.velocity(&plane.point) * dt
            } else {
                moved
            };
            match slot.response {
                Response::Penalty { kc, dc } => {
                    if depth > 0.0 {
                        b.f += n * (kc * depth);
                        b.h = b.h.plus(&Sym3::outer(&n).scale(kc));
                    }
                    if self.penalty_damps(i, plane) {
                        b.f -= n * (dc * moved.dot(&n) / dt);
                        b.h = b.h.plus(&Sym3::outer(&n).scale(dc / dt));
                    }
                }
                ref response => {
                    let (k, mu) = collider_law(response, self.detection.scale[i]);
                    let (law, gap) = if margin > 0.0 {
                        (normal_law(d, margin, k, n), Some(d))
                    } else {
                        ((n, k * depth, k), None)
                    };
                    b.contact(law, gap, mu, moved, 1.0, dt, gaps);
                }
            }
        }
    }

    /// Whether a penalty wall's damping acts on particle `i` over this step: when the
    /// particle was inside the wall at the step's start. The course's law damps while a
    /// particle is inside, a force that jumps where it enters; read at the solve's iterate,
    /// the step's equations can have no solution (outside undamped it enters, inside damped
    /// it leaves) and Newton's iterates cycle between the two. Read at the start, as an
    /// explicit stage reads it, the step's energy is smooth.
    fn penalty_damps(&self, i: usize, plane: &Plane) -> bool {
        self.detection.margin(self.model, i) - plane.normal.dot(&(self.start[i] - plane.point))
            > 0.0
    }

    fn pairs(&self, i: usize, x: &[Vec3], b: &mut Block, gaps: &mut impl GapSink) {
        for pair in self.detection.pairs_of(i) {
            let Some(c) = self.pair_contact(pair, x) else {
                continue;
            };
            let mine = pair.ids[..c.len]
                .iter()
                .zip(&c.w)
                .find(|(id, _)| **id as usize == i)
                .map_or(0.0, |(_, w)| *w);
            if mine == 0.0 {
                continue;
            }
            b.contact(
                (c.n, c.lambda, c.stiffness),
                Some(c.d),
                pair.mu,
                c.slip,
                mine,
                self.dt,
                gaps,
            );
        }
    }

    /// Pair `pair`'s contact at positions `x`, when it counts and its gap is within the
    /// band beyond its thickness: its stencil, normal, gap, normal force and the stencil's
    /// displacement over the step (relative to a moving feature).
    pub(in crate::integrator) fn pair_contact(
        &self,
        pair: &Pair,
        x: &[Vec3],
    ) -> Option<PairContact> {
        let (w, anchor, len, counts) = stencil(pair, x);
        if !counts {
            return None;
        }
        let mut gap = -anchor;
        let mut slip = Vec3::zeros();
        for (&id, &wk) in pair.ids[..len].iter().zip(&w) {
            let id = id as usize;
            gap += x[id] * wk;
            slip += (x[id] - self.start[id]) * wk;
        }
        let d = gap.norm();
        if d >= pair.h * (1.0 + BAND) {
            return None;
        }
        let n = if d > EPS {
            gap / d
        } else {
            // Touching: the direction the gap had at the step's start.
            let mut g0 = -anchor;
            for (&id, &wk) in pair.ids[..len].iter().zip(&w) {
                g0 += self.start[id as usize] * wk;
            }
            g0.try_normalize(EPS)?
        };
        if let Sides::Feature(_, carry) = pair.sides {
            slip -= carry;
        }
        let (_, lambda, stiffness) = normal_law(d, pair.h, pair.k, n);
        Some(PairContact {
            w,
            len,
            n,
            d,
            lambda,
            stiffness,
            slip,
        })
    }
}
