//! Springs: index pairs with rest length, stiffness and damping (docs/physics.md §1).

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

/// Below this length a spring has no direction and adds no force (docs/physics.md §1).
pub(crate) const DEGENERATE_LENGTH: f64 = 1e-12;

impl Spring {
    /// The force on particle `i` (particle `j` receives its negation), exactly as docs/physics.md §1:
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

/// The force on the `i` end of a spring from `d = x_i - x_j` and `dv = v_i - v_j` (docs/physics.md §1):
/// `(-ks (|d| - rest) - kd dv·u) u` with `u = d / |d|`; zero for a degenerate spring. Every
/// force path goes through [`spring_formula`], so they agree to the bit.
#[inline]
pub(crate) fn spring_force(d: Vec3, dv: Vec3, rest: f64, ks: f64, kd: f64) -> Vec3 {
    Vec3::from(spring_formula(
        [d.x, d.y, d.z],
        [dv.x, dv.y, dv.z],
        rest,
        ks,
        kd,
    ))
}

/// docs/physics.md §1's spring force, the one copy of the formula: every batch layout and
/// [`spring_force`] inline it, so all give the same bits. It has no branch (the degenerate
/// case is a select after the division), so a loop of it vectorises at the target's full
/// width: square roots and divisions, the bottleneck of a spring, then run several springs
/// per instruction.
#[inline(always)]
pub(crate) fn spring_formula(d: [f64; 3], dv: [f64; 3], rest: f64, ks: f64, kd: f64) -> [f64; 3] {
    let [dx, dy, dz] = d;
    let [vx, vy, vz] = dv;
    let len = (dx * dx + dy * dy + dz * dz).sqrt();
    // One division instead of three: the reciprocal scales all components. A degenerate
    // spring gets a zero direction, hence zero force, never 0·∞ = NaN.
    let inv = if len < DEGENERATE_LENGTH {
        0.0
    } else {
        1.0 / len
    };
    let (ux, uy, uz) = (dx * inv, dy * inv, dz * inv);
    let scale = -ks * (len - rest) - kd * (vx * ux + vy * uy + vz * uz);
    [ux * scale, uy * scale, uz * scale]
}

/// A batch of `L` springs for the force loop: each spring's end differences, rest length,
/// stiffness and damping go in, [`SpringBatch::run`] computes all their forces in one
/// vectorised loop, and each force comes out. The vectors' layout in between is the
/// implementation's: which one is faster depends on the instruction set (see
/// [`ComponentBatch`] and [`VectorBatch`]), never the result.
pub(crate) trait SpringBatch<const L: usize>: Default {
    /// The batch's rest lengths, stiffnesses and dampings.
    fn scalars(&mut self) -> &mut BatchScalars<L>;
    /// Sets spring `l`'s end differences.
    fn set_vectors(&mut self, l: usize, d: &Vec3, dv: &Vec3);
    /// Computes the forces of the first `n` springs.
    fn run(&mut self, n: usize);
    /// The force on the `i` end of spring `l`, after [`SpringBatch::run`].
    fn force(&self, l: usize) -> Vec3;

    /// Sets spring `l`'s end differences and rest length.
    #[inline(always)]
    fn set(&mut self, l: usize, d: &Vec3, dv: &Vec3, rest: f64) {
        self.set_vectors(l, d, dv);
        self.scalars().rest[l] = rest;
    }

    /// Sets spring `l`'s stiffness and damping.
    #[inline(always)]
    fn set_params(&mut self, l: usize, ks: f64, kd: f64) {
        let s = self.scalars();
        (s.ks[l], s.kd[l]) = (ks, kd);
    }

    /// Sets every spring's stiffness and damping.
    fn set_all_params(&mut self, ks: f64, kd: f64) {
        let s = self.scalars();
        (s.ks, s.kd) = ([ks; L], [kd; L]);
    }
}

/// The per-spring scalars of a batch, the same in every layout.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BatchScalars<const L: usize> {
    rest: [f64; L],
    ks: [f64; L],
    kd: [f64; L],
}

impl<const L: usize> Default for BatchScalars<L> {
    fn default() -> Self {
        Self {
            rest: [0.0; L],
            ks: [0.0; L],
            kd: [0.0; L],
        }
    }
}

/// `L` springs with each vector stored by component (`d[0]` holds every spring's x): the
/// vector loop loads whole registers of one component. The fastest layout with AVX2 and
/// SSE2, whose shuffles make deinterleaving 3-vectors cost more than the extra scalar
/// stores this layout takes to fill (cloth-256 on a Zen 3, AVX2, 1 thread: 112 → 125 M
/// spring updates/s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ComponentBatch<const L: usize> {
    d: [[f64; L]; 3],
    dv: [[f64; L]; 3],
    s: BatchScalars<L>,
    f: [[f64; L]; 3],
}

impl<const L: usize> Default for ComponentBatch<L> {
    fn default() -> Self {
        Self {
            d: [[0.0; L]; 3],
            dv: [[0.0; L]; 3],
            s: BatchScalars::default(),
            f: [[0.0; L]; 3],
        }
    }
}

impl<const L: usize> SpringBatch<L> for ComponentBatch<L> {
    fn scalars(&mut self) -> &mut BatchScalars<L> {
        &mut self.s
    }

    #[inline(always)]
    fn set_vectors(&mut self, l: usize, d: &Vec3, dv: &Vec3) {
        for c in 0..3 {
            self.d[c][l] = d[c];
            self.dv[c][l] = dv[c];
        }
    }

    #[inline(always)]
    fn run(&mut self, n: usize) {
        // An index loop over a bound the compiler can see (`n.min(L)`): it vectorises this
        // form best, without bounds checks.
        #[allow(clippy::needless_range_loop)]
        for l in 0..n.min(L) {
            let (d, dv) = (&self.d, &self.dv);
            let f = spring_formula(
                [d[0][l], d[1][l], d[2][l]],
                [dv[0][l], dv[1][l], dv[2][l]],
                self.s.rest[l],
                self.s.ks[l],
                self.s.kd[l],
            );
            for c in 0..3 {
                self.f[c][l] = f[c];
            }
        }
    }

    #[inline(always)]
    fn force(&self, l: usize) -> Vec3 {
        Vec3::new(self.f[0][l], self.f[1][l], self.f[2][l])
    }
}

/// `L` springs with each vector stored whole: filling and emptying the batch takes one
/// vector store or load per 3-vector instead of three scalars, and the compiler
/// deinterleaves in the vector loop. Faster with AVX-512 on some CPUs, whose two-source
/// permutes make that cheap (cloth-256 on a Zen 5, 1 thread: 188 → 201 M spring
/// updates/s against [`ComponentBatch`]), slower on others (a `jello.w` step on a Zen 4:
/// 150 µs against 104 µs): the AVX-512 kernel times both (`kernel/batch_choice.rs`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct VectorBatch<const L: usize> {
    d: [[f64; 3]; L],
    dv: [[f64; 3]; L],
    s: BatchScalars<L>,
    f: [[f64; 3]; L],
}

impl<const L: usize> Default for VectorBatch<L> {
    fn default() -> Self {
        Self {
            d: [[0.0; 3]; L],
            dv: [[0.0; 3]; L],
            s: BatchScalars::default(),
            f: [[0.0; 3]; L],
        }
    }
}

impl<const L: usize> SpringBatch<L> for VectorBatch<L> {
    fn scalars(&mut self) -> &mut BatchScalars<L> {
        &mut self.s
    }

    #[inline(always)]
    fn set_vectors(&mut self, l: usize, d: &Vec3, dv: &Vec3) {
        self.d[l] = [d.x, d.y, d.z];
        self.dv[l] = [dv.x, dv.y, dv.z];
    }

    #[inline(always)]
    fn run(&mut self, n: usize) {
        #[allow(clippy::needless_range_loop)]
        for l in 0..n.min(L) {
            let s = &self.s;
            self.f[l] = spring_formula(self.d[l], self.dv[l], s.rest[l], s.ks[l], s.kd[l]);
        }
    }

    #[inline(always)]
    fn force(&self, l: usize) -> Vec3 {
        Vec3::from(self.f[l])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `count` springs through a batch of layout `B`, `L` at a time (the last
    /// batch partly filled), and returns their forces.
    fn through<const L: usize, B: SpringBatch<L>>(springs: &[(Vec3, Vec3, [f64; 3])]) -> Vec<Vec3> {
        let mut out = Vec::new();
        for chunk in springs.chunks(L) {
            let mut batch = B::default();
            for (l, (d, dv, [rest, ks, kd])) in chunk.iter().enumerate() {
                batch.set(l, d, dv, *rest);
                batch.set_params(l, *ks, *kd);
            }
            batch.run(chunk.len());
            out.extend((0..chunk.len()).map(|l| batch.force(l)));
        }
        out
    }

    #[test]
    fn both_batch_layouts_give_the_formula_s_bits() {
        // Only the AVX-512 kernel uses whole vectors, and not every CPU runs it: this checks
        // both layouts on any machine, against the one formula.
        let mut unit = crate::assembly::kernel::unit_numbers(0x9e37_79b9_7f4a_7c15);
        let mut next = move || unit() - 0.5;
        let mut springs: Vec<_> = (0..999)
            .map(|k| {
                let d = Vec3::new(next(), next(), next()) * 10f64.powi(k % 7 - 3);
                let dv = Vec3::new(next(), next(), next());
                (d, dv, [next() + 0.5, 100.0 * (next() + 1.0), next() + 0.5])
            })
            .collect();
        // Coincident ends and ends just either side of the degenerate length.
        springs[3].0 = Vec3::zeros();
        springs[10].0 = Vec3::new(DEGENERATE_LENGTH * 0.5, 0.0, 0.0);
        springs[11].0 = Vec3::new(DEGENERATE_LENGTH * 2.0, 0.0, 0.0);
        let formula: Vec<Vec3> = springs
            .iter()
            .map(|(d, dv, [rest, ks, kd])| spring_force(*d, *dv, *rest, *ks, *kd))
            .collect();
        assert_eq!(formula[3], Vec3::zeros());
        assert_eq!(formula[10], Vec3::zeros());
        assert!(
            formula[11].x > 0.0,
            "a spring just above the cut-off pushes"
        );
        let bits = |f: &[Vec3]| -> Vec<u64> {
            f.iter()
                .flat_map(|v| v.iter().map(|c| c.to_bits()))
                .collect()
        };
        assert_eq!(
            bits(&through::<64, ComponentBatch<64>>(&springs)),
            bits(&formula)
        );
        assert_eq!(
            bits(&through::<4, ComponentBatch<4>>(&springs)),
            bits(&formula)
        );
        assert_eq!(
            bits(&through::<64, VectorBatch<64>>(&springs)),
            bits(&formula)
        );
        assert_eq!(
            bits(&through::<8, VectorBatch<8>>(&springs)),
            bits(&formula)
        );
    }
}
