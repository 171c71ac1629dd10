//! The group step of the run loop in AVX2 registers: four springs per instruction, the
//! upper ends' coordinates transposed from the particles' layout to the components' by
//! shuffles (the window they add into is by component already). Every lane does
//! [`crate::forces::spring::spring_formula`]'s operations in its order (no fused multiply-adds),
//! so the bits are the portable kernel's, as a test checks.

#![cfg(target_arch = "x86_64")]

use super::run_loop::{GROUP, Group};
use crate::forces::spring::DEGENERATE_LENGTH;
use std::arch::x86_64::{
    __m256d, _CMP_NLT_UQ, _mm256_add_pd, _mm256_and_pd, _mm256_blend_pd, _mm256_cmp_pd,
    _mm256_div_pd, _mm256_mul_pd, _mm256_permute2f128_pd, _mm256_set1_pd, _mm256_shuffle_pd,
    _mm256_sqrt_pd, _mm256_sub_pd,
};

#[target_feature(enable = "avx2")]
#[inline]
fn load(v: &[f64; GROUP]) -> __m256d {
    bytemuck::cast(*v)
}

#[target_feature(enable = "avx2")]
#[inline]
fn store(v: __m256d) -> [f64; GROUP] {
    bytemuck::cast(v)
}

/// Four particles' coordinates `[x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3]` as the vectors
/// `[x0 x1 x2 x3]`, `[y0 ..]`, `[z0 ..]`.
#[target_feature(enable = "avx2")]
#[inline]
fn transpose_in(p: &[f64; 3 * GROUP]) -> [__m256d; 3] {
    let quarter = |k: usize| load(p[4 * k..4 * k + 4].try_into().expect("four values"));
    let (a, b, c) = (quarter(0), quarter(1), quarter(2));
    let xy02 = _mm256_blend_pd::<0b1100>(a, b); // x0 y0 x2 y2
    let zx13 = _mm256_permute2f128_pd::<0x21>(a, c); // z0 x1 z2 x3
    let yz13 = _mm256_blend_pd::<0b1100>(b, c); // y1 z1 y3 z3
    [
        _mm256_shuffle_pd::<0b1010>(xy02, zx13),
        _mm256_shuffle_pd::<0b0101>(xy02, yz13),
        _mm256_shuffle_pd::<0b1010>(zx13, yz13),
    ]
}

/// [`super::run_loop::group_by_lane`] in AVX2 registers.
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) fn group_avx2(g: Group<GROUP>) {
    let flat = |p: &[[f64; 3]; GROUP]| -> [f64; 3 * GROUP] { bytemuck::cast(*p) };
    let xb = transpose_in(&flat(g.xb));
    let vb = transpose_in(&flat(g.vb));
    let d: [__m256d; 3] = std::array::from_fn(|c| _mm256_sub_pd(load(g.x[c]), xb[c]));
    let dv: [__m256d; 3] = std::array::from_fn(|c| _mm256_sub_pd(load(g.v[c]), vb[c]));
    let sq = |v: __m256d| _mm256_mul_pd(v, v);
    let len = _mm256_sqrt_pd(_mm256_add_pd(_mm256_add_pd(sq(d[0]), sq(d[1])), sq(d[2])));
    // `len < DEGENERATE_LENGTH ? 0 : 1 / len`, NaN taking the division as in the formula.
    let keep = _mm256_cmp_pd::<_CMP_NLT_UQ>(len, _mm256_set1_pd(DEGENERATE_LENGTH));
    let inv = _mm256_and_pd(keep, _mm256_div_pd(_mm256_set1_pd(1.0), len));
    let u: [__m256d; 3] = std::array::from_fn(|c| _mm256_mul_pd(d[c], inv));
    let dot = _mm256_add_pd(
        _mm256_add_pd(_mm256_mul_pd(dv[0], u[0]), _mm256_mul_pd(dv[1], u[1])),
        _mm256_mul_pd(dv[2], u[2]),
    );
    let neg_ks = load(&g.ks.map(|k| -k));
    let stretch = _mm256_sub_pd(len, load(&g.rest));
    let scale = _mm256_sub_pd(
        _mm256_mul_pd(neg_ks, stretch),
        _mm256_mul_pd(load(&g.kd), dot),
    );
    let f: [__m256d; 3] = std::array::from_fn(|c| _mm256_mul_pd(u[c], scale));
    for (c, keep) in g.keep.into_iter().enumerate() {
        *keep = store(f[c]);
    }
    for (c, out) in g.out.into_iter().enumerate() {
        *out = store(_mm256_sub_pd(load(out), f[c]));
    }
}
