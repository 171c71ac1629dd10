//! A proximity as the contact phase resolves it (docs/physics.md §3.2): weights on up to
//! four particles whose sum is the gap, the gap's normal, the gap to keep, and how its
//! velocity responds.

use crate::collider::response::Response;
use crate::particles::Vec3;

/// Gaps shorter than this have no direction of their own.
const EPS: f64 = 1e-12;

/// How a stencil's velocity responds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Rule {
    /// Surface against surface: inelastic, Coulomb friction with this coefficient.
    Coulomb(f64),
    /// Against a collider with restitution `cr` and Coulomb friction `mu`.
    Bounce { cr: f64, mu: f64 },
    /// Against a stick collider: the touching point stops.
    Stop,
}

impl Rule {
    pub(super) fn of(response: &Response) -> Self {
        match *response {
            Response::Restitution { cr, friction } => Self::Bounce { cr, mu: friction },
            Response::Stick => Self::Stop,
            Response::Penalty { .. } => Self::Bounce { cr: 0.0, mu: 0.0 },
        }
    }
}

/// A proximity: `Σ w_k x_k - anchor` is the gap between its two sides.
#[derive(Clone, Copy, Debug)]
pub(super) struct Stencil {
    pub(super) ids: [u32; 4],
    pub(super) w: [f64; 4],
    /// 3 (a triangle against a fixed collider point) or 4.
    pub(super) len: usize,
    /// The collider's point (zero for surface pairs).
    pub(super) anchor: Vec3,
    /// The collider's velocity at `anchor` over the step (zero for surface pairs and still
    /// colliders).
    pub(super) anchor_velocity: Vec3,
    /// The gap's unit normal.
    pub(super) n: Vec3,
    /// The gap to keep, metres.
    pub(super) h: f64,
    pub(super) rule: Rule,
}

impl Stencil {
    /// A surface pair: weights `w` on particles `ids`, kept `h` apart, friction `mu`.
    pub(super) fn surface(ids: [u32; 4], w: [f64; 4], h: f64, mu: f64) -> Self {
        Self {
            ids,
            w,
            len: 4,
            anchor: Vec3::zeros(),
            anchor_velocity: Vec3::zeros(),
            n: Vec3::zeros(),
            h,
            rule: Rule::Coulomb(mu),
        }
    }

    pub(super) fn gap(&self, x: &[Vec3]) -> Vec3 {
        let mut g = -self.anchor;
        for k in 0..self.len {
            g += x[self.ids[k] as usize] * self.w[k];
        }
        g
    }

    /// `Σ w_k² / m_k`: how far the gap moves per unit impulse.
    pub(super) fn compliance(&self, inv_mass: &[f64]) -> f64 {
        (0..self.len)
            .map(|k| self.w[k] * self.w[k] * inv_mass[self.ids[k] as usize])
            .sum()
    }

    /// Adds `w_k / m_k · j` to each particle's entry of `y`.
    pub(super) fn spread(&self, inv_mass: &[f64], y: &mut [Vec3], j: Vec3) {
        for k in 0..self.len {
            let i = self.ids[k] as usize;
            y[i] += j * (self.w[k] * inv_mass[i]);
        }
    }

    /// Orients the stencil at `x` (see the module docs) and returns its signed gap along the
    /// normal, or `None` when no direction can be told.
    pub(super) fn orient(&mut self, x: &[Vec3], x0: &[Vec3]) -> Option<f64> {
        let now = self.gap(x);
        let start = self.gap(x0);
        let d = now.norm();
        if d > EPS && now.dot(&start) > 0.0 {
            self.n = now / d;
            Some(d)
        } else {
            let d0 = start.norm();
            (d0 > EPS).then(|| {
                self.n = start / d0;
                now.dot(&self.n)
            })
        }
    }
}
