//! Springs: index pairs with rest length, stiffness and damping (SPEC §1).

use crate::particles::Vec3;

/// What a spring holds together; used for drawing and statistics, never by the physics.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SpringKind {
    /// Between axis neighbours of a chain, grid or lattice.
    Structural,
    /// Along face or body diagonals; resists shearing.
    Shear,
    /// Between axis neighbours two apart; resists bending.
    Bend,
    /// Anything else (explicit pairs).
    Other,
}

impl SpringKind {
    /// All kinds, in a fixed order.
    pub const ALL: [SpringKind; 4] = [Self::Structural, Self::Shear, Self::Bend, Self::Other];

    /// The lowercase name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Structural => "structural",
            Self::Shear => "shear",
            Self::Bend => "bend",
            Self::Other => "other",
        }
    }
}

/// A damped spring between particles `i` and `j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// First particle.
    pub i: u32,
    /// Second particle.
    pub j: u32,
    /// Rest length in metres.
    pub rest: f64,
    /// Stiffness in N/m.
    pub ks: f64,
    /// Damping along the spring in N·s/m.
    pub kd: f64,
    /// What the spring holds together.
    pub kind: SpringKind,
}

/// Below this length a spring has no direction and adds no force (SPEC §1).
pub const DEGENERATE_LENGTH: f64 = 1e-12;

impl Spring {
    /// The force on particle `i` (particle `j` receives its negation), exactly as SPEC §1:
    /// `-ks (L - l) u - kd ((v_i - v_j) · u) u` with `u = (x_i - x_j) / L`.
    ///
    /// ```
    /// use hooke_core::{Spring, SpringKind, Vec3};
    /// let s = Spring { i: 0, j: 1, rest: 1.0, ks: 10.0, kd: 0.0, kind: SpringKind::Other };
    /// // Stretched by 0.5 along +x: particle i is pulled back towards j.
    /// let f = s.force(&Vec3::new(1.5, 0.0, 0.0), &Vec3::zeros(), &Vec3::zeros(), &Vec3::zeros());
    /// assert_eq!(f, Vec3::new(-5.0, 0.0, 0.0));
    /// ```
    #[inline]
    pub fn force(&self, xi: &Vec3, xj: &Vec3, vi: &Vec3, vj: &Vec3) -> Vec3 {
        spring_force(xi - xj, vi - vj, self.rest, self.ks, self.kd)
    }

    /// Elastic potential energy `ks (L - l)² / 2` in joules.
    pub fn energy(&self, xi: &Vec3, xj: &Vec3) -> f64 {
        let stretch = (xi - xj).norm() - self.rest;
        0.5 * self.ks * stretch * stretch
    }
}

/// The force on the `i` end of a spring from `d = x_i - x_j` and `dv = v_i - v_j` (SPEC §1):
/// `(-ks (|d| - rest) - kd dv·u) u` with `u = d / |d|`; zero for a degenerate spring. Every
/// force path goes through [`spring_lanes`], so they agree to the bit.
#[inline]
pub(crate) fn spring_force(d: Vec3, dv: Vec3, rest: f64, ks: f64, kd: f64) -> Vec3 {
    let mut s = Lanes::<1>::default();
    s.set(0, (&d, &dv), rest);
    s.ks = [ks];
    s.kd = [kd];
    let mut f = [[0.0; 3]];
    spring_lanes(&s, 1, &mut f);
    Vec3::from(f[0])
}

/// `L` springs' inputs for [`spring_lanes`]: each spring's vectors whole (the compiler
/// deinterleaves them in the vector loop), rest length, stiffness and damping.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lanes<const L: usize> {
    pub d: [[f64; 3]; L],
    pub dv: [[f64; 3]; L],
    pub rest: [f64; L],
    pub ks: [f64; L],
    pub kd: [f64; L],
}

impl<const L: usize> Default for Lanes<L> {
    fn default() -> Self {
        Self {
            d: [[0.0; 3]; L],
            dv: [[0.0; 3]; L],
            rest: [0.0; L],
            ks: [0.0; L],
            kd: [0.0; L],
        }
    }
}

impl<const L: usize> Lanes<L> {
    /// Sets lane `l`'s end differences and rest length.
    #[inline(always)]
    pub fn set(&mut self, l: usize, (d, dv): (&Vec3, &Vec3), rest: f64) {
        self.d[l] = [d.x, d.y, d.z];
        self.dv[l] = [dv.x, dv.y, dv.z];
        self.rest[l] = rest;
    }
}

/// [`spring_force`] for the first `n` of `L` springs side by side, one force per spring
/// out. The loop body has no branch (the degenerate case is a select after the division),
/// so the compiler vectorises it at the target's full width: square roots and divisions,
/// the bottleneck of a spring, then run several springs per instruction.
#[inline(always)]
pub(crate) fn spring_lanes<const L: usize>(s: &Lanes<L>, n: usize, f: &mut [[f64; 3]; L]) {
    // An index loop over a bound the compiler can see (`n.min(L)`): it vectorises this
    // form best, without bounds checks.
    #[allow(clippy::needless_range_loop)]
    for l in 0..n.min(L) {
        let [dx, dy, dz] = s.d[l];
        let [vx, vy, vz] = s.dv[l];
        let len = (dx * dx + dy * dy + dz * dz).sqrt();
        // One division instead of three: the reciprocal scales all components. A degenerate
        // spring gets a zero direction, hence zero force, never 0·∞ = NaN.
        let inv = if len < DEGENERATE_LENGTH {
            0.0
        } else {
            1.0 / len
        };
        let (ux, uy, uz) = (dx * inv, dy * inv, dz * inv);
        let scale = -s.ks[l] * (len - s.rest[l]) - s.kd[l] * (vx * ux + vy * uy + vz * uz);
        f[l] = [ux * scale, uy * scale, uz * scale];
    }
}
