//! The implicit integrator's 3×3 blocks: symmetric matrices, and each spring's stiffness and
//! damping derivatives as a pair of them.

use crate::assembly::{Assembly, PARTITION_MIN};
use crate::particles::Vec3;
use rayon::prelude::*;

/// A symmetric 3×3 matrix: `[xx, yy, zz, xy, xz, yz]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sym3(pub [f64; 6]);

impl Sym3 {
    /// `u uᵀ`.
    pub(crate) fn outer(u: &Vec3) -> Self {
        Self([
            u.x * u.x,
            u.y * u.y,
            u.z * u.z,
            u.x * u.y,
            u.x * u.z,
            u.y * u.z,
        ])
    }

    /// `s · self`.
    pub(crate) fn scale(self, s: f64) -> Self {
        Self(self.0.map(|v| v * s))
    }

    /// `self + s I`.
    pub(crate) fn plus_identity(mut self, s: f64) -> Self {
        for k in 0..3 {
            self.0[k] += s;
        }
        self
    }

    /// `self + other`.
    pub(crate) fn plus(self, other: &Sym3) -> Self {
        Self(std::array::from_fn(|k| self.0[k] + other.0[k]))
    }

    /// `self · v`.
    #[inline]
    pub(crate) fn mul(&self, v: &Vec3) -> Vec3 {
        let [xx, yy, zz, xy, xz, yz] = self.0;
        Vec3::new(
            xx * v.x + xy * v.y + xz * v.z,
            xy * v.x + yy * v.y + yz * v.z,
            xz * v.x + yz * v.y + zz * v.z,
        )
    }

    /// The inverse, or `None` when the matrix is singular.
    pub(crate) fn inverse(&self) -> Option<Self> {
        let [a, d, f, b, c, e] = self.0;
        // Cofactors of [[a b c] [b d e] [c e f]].
        let (ca, cb, cc) = (d * f - e * e, c * e - b * f, b * e - c * d);
        let det = a * ca + b * cb + c * cc;
        if det.abs() <= f64::MIN_POSITIVE {
            return None;
        }
        let inv = 1.0 / det;
        Some(Self([
            ca * inv,
            (a * f - c * c) * inv,
            (a * d - b * b) * inv,
            cb * inv,
            cc * inv,
            (b * c - a * e) * inv,
        ]))
    }
}

/// Each spring's force derivatives at `x`, in `asm`'s spring order, as positive
/// semi-definite blocks (in the contract's names, `L = |x_i - x_j|` the length now, `l` the
/// rest length, `u = (x_i - x_j)/L`): the elastic `Kₛ = ks (u uᵀ + max(0, 1 - l/L)(I - u uᵀ))`,
/// so that `∂f_i/∂x_i = -Kₛ`, and the damping `Dₛ = kd u uᵀ`, `∂f_i/∂v_i = -Dₛ`. The
/// transverse term is clamped at zero for compressed springs (Choi & Ko 2002), which keeps
/// the implicit system positive definite.
pub(super) fn spring_blocks(asm: &Assembly, x: &[Vec3], out: &mut Vec<[Sym3; 2]>) {
    out.resize(asm.springs(), [Sym3::default(); 2]);
    let block = |k: usize| {
        let [i, j] = asm.ends(k);
        let d = x[i] - x[j];
        let len = d.norm();
        if len < crate::forces::spring::DEGENERATE_LENGTH {
            return [Sym3::default(); 2];
        }
        let u = d * (1.0 / len);
        let [ks, kd] = asm.params(k);
        let uu = Sym3::outer(&u);
        let transverse = (1.0 - asm.rest(k) / len).max(0.0);
        let elastic = uu
            .scale(ks * (1.0 - transverse))
            .plus_identity(ks * transverse);
        [elastic, uu.scale(kd)]
    };
    if out.len() <= PARTITION_MIN {
        out.iter_mut().enumerate().for_each(|(k, o)| *o = block(k));
    } else {
        out.par_iter_mut()
            .with_min_len(PARTITION_MIN)
            .enumerate()
            .for_each(|(k, o)| *o = block(k));
    }
}
