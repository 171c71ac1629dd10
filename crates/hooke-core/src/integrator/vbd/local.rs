//! One particle's block update: a Newton step on its share of the implicit-Euler energy,
//! the others held where they are (docs/physics.md §4.1).

use super::detect::{Detection, collider_law};
use super::graph::Graph;
use super::pairs::{Sides, stencil};
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

/// What every particle's update reads: the step's data and the last detection.
pub(super) struct Local<'a> {
    pub(super) model: &'a Model,
    pub(super) graph: &'a Graph,
    pub(super) detection: &'a Detection,
    pub(super) mass: &'a [f64],
    /// Positions at the step's start.
    pub(super) start: &'a [Vec3],
    /// Inertial targets `x + dt v + dt² f_ext / m`.
    pub(super) target: &'a [Vec3],
    pub(super) dt: f64,
}

/// A gradient and Hessian being summed: `f` is minus the gradient (a force), and the
/// contacts' gaps as `(d, g)`: the step `s` changes gap `d` by about `g · s`.
struct Block {
    f: Vec3,
    h: Sym3,
    gaps: Gaps,
}

/// Gaps kept inline: a particle rarely has more than a few contacts, and a heap
/// allocation per particle and iteration would cost more than its solve.
const INLINE_GAPS: usize = 16;

#[derive(Default)]
struct Gaps {
    count: usize,
    inline: [(f64, Vec3); INLINE_GAPS],
    more: Vec<(f64, Vec3)>,
}

impl Gaps {
    fn push(&mut self, gap: (f64, Vec3)) {
        if self.count < INLINE_GAPS {
            self.inline[self.count] = gap;
            self.count += 1;
        } else {
            self.more.push(gap);
        }
    }

    fn iter(&self) -> impl Iterator<Item = &(f64, Vec3)> {
        self.inline[..self.count].iter().chain(&self.more)
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
    ) {
        let nn = Sym3::outer(&n);
        self.h = self.h.plus(&nn.scale(k * w * w));
        if let Some(d) = gap {
            self.gaps.push((d, n * w));
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
        let c = if mu.is_infinite() {
            k
        } else {
            mu * lambda / slide.norm().max(STATIC_SPEED * dt)
        };
        self.f -= slide * (c * w);
        self.h = self.h.plus(&tangent.scale(c * w * w));
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
    /// Particle `i`'s position after one Newton step on its local energy, at positions `x`.
    pub(super) fn solve(&self, i: usize, x: &[Vec3]) -> Vec3 {
        let b = self.block(i, x);
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
        let scale = b
            .gaps
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
    pub(super) fn force(&self, i: usize, x: &[Vec3]) -> Vec3 {
        self.block(i, x).f
    }

    /// What particle `i` adds to its body's translation at positions `x`: its force and
    /// Hessian block without the springs' terms, which cancel over a body moved as a whole
    /// (and so are not computed).
    pub(super) fn translation(&self, i: usize, x: &[Vec3]) -> (Vec3, Sym3) {
        let b = self.terms(i, x, false);
        (b.f, b.h)
    }

    /// Particle `i`'s force and Hessian block at positions `x`.
    fn block(&self, i: usize, x: &[Vec3]) -> Block {
        self.terms(i, x, true)
    }

    /// Particle `i`'s force and Hessian block at positions `x`, its springs' terms with
    /// `springs`.
    fn terms(&self, i: usize, x: &[Vec3], springs: bool) -> Block {
        let dt = self.dt;
        let inertia = self.mass[i] / (dt * dt);
        let xi = x[i];
        let moved = xi - self.start[i];
        let mut b = Block {
            f: (self.target[i] - xi) * inertia,
            h: Sym3::default().plus_identity(inertia),
            gaps: Gaps::default(),
        };
        let model = self.model;
        if model.has_drag() {
            let drag = model.drag_on(self.mass[i]) / dt;
            b.f -= moved * drag;
            b.h = b.h.plus_identity(drag);
        }
        let mine = if springs { self.graph.of(i) } else { &[] };
        for nb in mine {
            let j = nb.other as usize;
            let d = xi - x[j];
            let len = d.norm();
            if len < crate::forces::spring::DEGENERATE_LENGTH {
                continue;
            }
            let u = d / len;
            let rate = (moved - (x[j] - self.start[j])).dot(&u) / dt;
            b.f -= u * (nb.ks * (len - nb.rest) + nb.kd * rate);
            // The transverse term is dropped for compressed springs, which keeps the block
            // positive definite (as the implicit integrator's, Choi & Ko 2002).
            let transverse = (1.0 - nb.rest / len).max(0.0);
            b.h = b.h.plus(
                &Sym3::outer(&u)
                    .scale(nb.ks * (1.0 - transverse) + nb.kd / dt)
                    .plus_identity(nb.ks * transverse),
            );
        }
        for a in model.attachments.iter().filter(|a| a.particle == i) {
            b.f -= (xi - a.target) * a.ks + moved * (a.kd / dt);
            b.h = b.h.plus_identity(a.ks + a.kd / dt);
        }
        self.colliders(i, &xi, moved, &mut b);
        self.pairs(i, x, &mut b);
        b
    }

    fn colliders(&self, i: usize, xi: &Vec3, moved: Vec3, b: &mut Block) {
        let touches = self.detection.touches[i].planes();
        if touches.is_empty() {
            return;
        }
        let margin = self.detection.margin(self.model, i);
        let dt = self.dt;
        for plane in touches {
            let n = plane.normal;
            let d = n.dot(&(xi - plane.point));
            if d >= margin * (1.0 + BAND) {
                continue;
            }
            let depth = margin - d;
            let slot = &self.model.colliders[plane.collider as usize];
            // Damping and friction read the motion relative to a moving collider's surface.
            let moved = if slot.shape.is_moving() {
                moved - slot.shape.velocity(&plane.point) * dt
            } else {
                moved
            };
            match slot.response {
                Response::Penalty { kc, dc } => {
                    if depth <= 0.0 {
                        continue;
                    }
                    b.f += n * (kc * depth - dc * moved.dot(&n) / dt);
                    b.h = b.h.plus(&Sym3::outer(&n).scale(kc + dc / dt));
                }
                ref response => {
                    let (k, mu) = collider_law(response, self.detection.scale[i]);
                    let (law, gap) = if margin > 0.0 {
                        (normal_law(d, margin, k, n), Some(d))
                    } else {
                        ((n, k * depth, k), None)
                    };
                    b.contact(law, gap, mu, moved, 1.0, dt);
                }
            }
        }
    }

    fn pairs(&self, i: usize, x: &[Vec3], b: &mut Block) {
        for pair in self.detection.pairs_of(i) {
            let (w, anchor, len, counts) = stencil(pair, x);
            if !counts {
                continue;
            }
            let mut gap = -anchor;
            let mut slip = Vec3::zeros();
            let mut mine = 0.0;
            for (&id, &wk) in pair.ids[..len].iter().zip(&w) {
                let id = id as usize;
                gap += x[id] * wk;
                slip += (x[id] - self.start[id]) * wk;
                if id == i {
                    mine = wk;
                }
            }
            let d = gap.norm();
            if d >= pair.h * (1.0 + BAND) || mine == 0.0 {
                continue;
            }
            let n = if d > EPS {
                gap / d
            } else {
                // Touching: the direction the gap had at the step's start.
                let mut g0 = -anchor;
                for (&id, &wk) in pair.ids[..len].iter().zip(&w) {
                    g0 += self.start[id as usize] * wk;
                }
                match g0.try_normalize(EPS) {
                    Some(n) => n,
                    None => continue,
                }
            };
            if let Sides::Feature(_, carry) = pair.sides {
                slip -= carry;
            }
            let law = normal_law(d, pair.h, pair.k, n);
            b.contact(law, Some(d), pair.mu, slip, mine, self.dt);
        }
    }
}
