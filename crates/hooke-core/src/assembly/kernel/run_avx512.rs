//! The group step of the run loop in AVX-512 registers: eight springs per instruction,
//! the upper ends' coordinates transposed from the particles' layout to the components'
//! by two-source permutes (the window they add into is by component already). Every lane
//! does [`crate::forces::spring::spring_formula`]'s operations in its order (no fused
//! multiply-adds), so the bits are the portable kernel's, as a test checks.

#![cfg(target_arch = "x86_64")]

use super::run_loop::Group;
use crate::forces::spring::DEGENERATE_LENGTH;
use std::arch::x86_64::{
    __m512d, __m512i, _CMP_NLT_UQ, _mm512_add_pd, _mm512_cmp_pd_mask, _mm512_div_pd,
    _mm512_maskz_mov_pd, _mm512_mul_pd, _mm512_permutex2var_pd, _mm512_set1_pd, _mm512_sqrt_pd,
    _mm512_sub_pd,
};

/// Springs per group.
pub(crate) const WIDE: usize = 8;

/// Eight particles' coordinates, flat.
type Flat = [f64; 3 * WIDE];

/// Two-source permute indices: `0..8` pick from the first vector, `8..16` from the second.
#[inline(always)]
fn index(i: [i64; WIDE]) -> __m512i {
    bytemuck::cast(i)
}

/// For component `c`: picks from the first two thirds of eight particles' flat
/// coordinates, then the last third, (particle `l`'s component at `3 l + c`).
const GATHER: [[[i64; WIDE]; 2]; 3] = [
    [[0, 3, 6, 9, 12, 15, 0, 0], [0, 1, 2, 3, 4, 5, 10, 13]],
    [[1, 4, 7, 10, 13, 0, 0, 0], [0, 1, 2, 3, 4, 8, 11, 14]],
    [[2, 5, 8, 11, 14, 0, 0, 0], [0, 1, 2, 3, 4, 9, 12, 15]],
];

#[inline(always)]
fn load(v: &[f64; WIDE]) -> __m512d {
    bytemuck::cast(*v)
}

#[inline(always)]
fn store(v: __m512d) -> [f64; WIDE] {
    bytemuck::cast(v)
}

/// Eight particles' flat coordinates as the vectors `[x0 .. x7]`, `[y0 ..]`, `[z0 ..]`.
#[target_feature(enable = "avx512f")]
#[inline]
fn transpose_in(p: &Flat) -> [__m512d; 3] {
    let third = |t: usize| load(p[8 * t..8 * t + 8].try_into().expect("eight values"));
    let (a, b, c) = (third(0), third(1), third(2));
    std::array::from_fn(|k| {
        let [first, then] = GATHER[k];
        let ab = _mm512_permutex2var_pd(a, index(first), b);
        _mm512_permutex2var_pd(ab, index(then), c)
    })
}

/// [`super::run_loop::group_by_lane`] in AVX-512 registers.
#[target_feature(enable = "avx512f")]
#[inline]
pub(crate) fn group_avx512(g: Group<WIDE>) {
    let flat = |p: &[[f64; 3]; WIDE]| -> Flat { bytemuck::cast(*p) };
    let xb = transpose_in(&flat(g.xb));
    let vb = transpose_in(&flat(g.vb));
    let d: [__m512d; 3] = std::array::from_fn(|c| _mm512_sub_pd(load(g.x[c]), xb[c]));
    let dv: [__m512d; 3] = std::array::from_fn(|c| _mm512_sub_pd(load(g.v[c]), vb[c]));
    let sq = |v: __m512d| _mm512_mul_pd(v, v);
    let len = _mm512_sqrt_pd(_mm512_add_pd(_mm512_add_pd(sq(d[0]), sq(d[1])), sq(d[2])));
    // `len < DEGENERATE_LENGTH ? 0 : 1 / len`, NaN taking the division as in the formula.
    let keep = _mm512_cmp_pd_mask::<_CMP_NLT_UQ>(len, _mm512_set1_pd(DEGENERATE_LENGTH));
    let inv = _mm512_maskz_mov_pd(keep, _mm512_div_pd(_mm512_set1_pd(1.0), len));
    let u: [__m512d; 3] = std::array::from_fn(|c| _mm512_mul_pd(d[c], inv));
    let dot = _mm512_add_pd(
        _mm512_add_pd(_mm512_mul_pd(dv[0], u[0]), _mm512_mul_pd(dv[1], u[1])),
        _mm512_mul_pd(dv[2], u[2]),
    );
    let neg_ks = load(&g.ks.map(|k| -k));
    let stretch = _mm512_sub_pd(len, load(&g.rest));
    let scale = _mm512_sub_pd(
        _mm512_mul_pd(neg_ks, stretch),
        _mm512_mul_pd(load(&g.kd), dot),
    );
    let f: [__m512d; 3] = std::array::from_fn(|c| _mm512_mul_pd(u[c], scale));
    for (c, keep) in g.keep.into_iter().enumerate() {
        *keep = store(f[c]);
    }
    for (c, out) in g.out.into_iter().enumerate() {
        *out = store(_mm512_sub_pd(load(out), f[c]));
    }
}
