//! The lanes' sum in AVX-512 and AVX2 registers: one body over a small vector type, so that
//! both do the same operations in the same order.

#![allow(unsafe_code)]

use super::{LANES, Row, Stream};
use crate::assembly::kernel::Kernel;
use crate::integrator::Sym3;
use crate::integrator::vbd::local::{Block, Local};
use crate::particles::Vec3;
use std::arch::x86_64::{
    __m128i, __m256d, __m256i, __m512d, __mmask8, _CMP_GT_OQ, _CMP_LT_OQ, _CMP_NLT_UQ,
    _mm_loadu_si128, _mm256_add_pd, _mm256_and_pd, _mm256_blendv_pd, _mm256_cmp_pd, _mm256_div_pd,
    _mm256_i32gather_pd, _mm256_loadu_pd, _mm256_loadu_si256, _mm256_mul_pd, _mm256_set1_pd,
    _mm256_sqrt_pd, _mm256_storeu_pd, _mm256_sub_pd, _mm512_add_pd, _mm512_cmp_pd_mask,
    _mm512_div_pd, _mm512_i32gather_pd, _mm512_loadu_pd, _mm512_mask_blend_pd, _mm512_mul_pd,
    _mm512_set1_pd, _mm512_sqrt_pd, _mm512_storeu_pd, _mm512_sub_pd,
};

/// A vector of `f64` lanes and the operations the sum needs, each lane correctly rounded
/// as its scalar operation is. Every method requires the CPU to have the type's
/// instructions (the caller's `target_feature`).
trait Wide: Copy {
    const WIDTH: usize;
    type Mask: Copy;
    unsafe fn splat(v: f64) -> Self;
    /// `WIDTH` values from `p`.
    unsafe fn load(p: *const f64) -> Self;
    /// `base[index[l]]` in each lane `l` (`index`: `WIDTH` `i32`s).
    unsafe fn gather(base: *const f64, index: *const i32) -> Self;
    unsafe fn store(self, p: *mut f64);
    unsafe fn add(self, b: Self) -> Self;
    unsafe fn sub(self, b: Self) -> Self;
    unsafe fn mul(self, b: Self) -> Self;
    unsafe fn div(self, b: Self) -> Self;
    unsafe fn sqrt(self) -> Self;
    /// `self < b`, false where either is NaN.
    unsafe fn lt(self, b: Self) -> Self::Mask;
    /// `self > b`, false where either is NaN.
    unsafe fn gt(self, b: Self) -> Self::Mask;
    /// `!(self < b)`: true where either is NaN.
    unsafe fn not_lt(self, b: Self) -> Self::Mask;
    unsafe fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// `yes` where `m`, otherwise `no`.
    unsafe fn select(m: Self::Mask, yes: Self, no: Self) -> Self;
}

impl Wide for __m512d {
    const WIDTH: usize = 8;
    type Mask = __mmask8;
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn splat(v: f64) -> Self {
        _mm512_set1_pd(v)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn load(p: *const f64) -> Self {
        // SAFETY: the caller gives addresses of `WIDTH` values.
        unsafe { _mm512_loadu_pd(p) }
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn gather(base: *const f64, index: *const i32) -> Self {
        // SAFETY: the caller gives addresses of `WIDTH` values.
        unsafe { _mm512_i32gather_pd::<8>(_mm256_loadu_si256(index as *const __m256i), base) }
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn store(self, p: *mut f64) {
        // SAFETY: the caller gives addresses of `WIDTH` values.
        unsafe { _mm512_storeu_pd(p, self) }
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn add(self, b: Self) -> Self {
        _mm512_add_pd(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn sub(self, b: Self) -> Self {
        _mm512_sub_pd(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn mul(self, b: Self) -> Self {
        _mm512_mul_pd(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn div(self, b: Self) -> Self {
        _mm512_div_pd(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn sqrt(self) -> Self {
        _mm512_sqrt_pd(self)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn lt(self, b: Self) -> Self::Mask {
        _mm512_cmp_pd_mask::<_CMP_LT_OQ>(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn gt(self, b: Self) -> Self::Mask {
        _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn not_lt(self, b: Self) -> Self::Mask {
        _mm512_cmp_pd_mask::<_CMP_NLT_UQ>(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask {
        a & b
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    unsafe fn select(m: Self::Mask, yes: Self, no: Self) -> Self {
        _mm512_mask_blend_pd(m, no, yes)
    }
}

impl Wide for __m256d {
    const WIDTH: usize = 4;
    type Mask = __m256d;
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn splat(v: f64) -> Self {
        _mm256_set1_pd(v)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn load(p: *const f64) -> Self {
        // SAFETY: the caller gives addresses of `WIDTH` values.
        unsafe { _mm256_loadu_pd(p) }
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn gather(base: *const f64, index: *const i32) -> Self {
        // SAFETY: the caller gives addresses of `WIDTH` values.
        unsafe { _mm256_i32gather_pd::<8>(base, _mm_loadu_si128(index as *const __m128i)) }
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn store(self, p: *mut f64) {
        // SAFETY: the caller gives addresses of `WIDTH` values.
        unsafe { _mm256_storeu_pd(p, self) }
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn add(self, b: Self) -> Self {
        _mm256_add_pd(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn sub(self, b: Self) -> Self {
        _mm256_sub_pd(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn mul(self, b: Self) -> Self {
        _mm256_mul_pd(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn div(self, b: Self) -> Self {
        _mm256_div_pd(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn sqrt(self) -> Self {
        _mm256_sqrt_pd(self)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn lt(self, b: Self) -> Self::Mask {
        _mm256_cmp_pd::<_CMP_LT_OQ>(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn gt(self, b: Self) -> Self::Mask {
        _mm256_cmp_pd::<_CMP_GT_OQ>(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn not_lt(self, b: Self) -> Self::Mask {
        _mm256_cmp_pd::<_CMP_NLT_UQ>(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask {
        _mm256_and_pd(a, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn select(m: Self::Mask, yes: Self, no: Self) -> Self {
        _mm256_blendv_pd(no, yes, m)
    }
}

/// `[e(0), e(1), e(2)]` for an expression `e` of `$c`, written out: a closure would be a
/// function of its own, compiled without the caller's vector instructions.
macro_rules! each {
    ($c:ident => $e:expr) => {
        [
            {
                let $c = 0;
                $e
            },
            {
                let $c = 1;
                $e
            },
            {
                let $c = 2;
                $e
            },
        ]
    };
}

/// One block's sum (see [`super::Lanes::sum`]) with `kernel`'s instructions, into `out`
/// (one entry per particle of the block).
pub(super) fn sum(kernel: Kernel, args: (&Local<'_>, &[Vec3], &Stream, usize), out: &mut [Block]) {
    match kernel {
        // SAFETY: a kernel is only ever chosen on a CPU that has its instructions
        // (`Kernel::detect`, `Simulation::set_kernel`).
        Kernel::Avx512 => unsafe { sum_avx512(args, out) },
        // SAFETY: as above.
        _ => unsafe { sum_avx2(args, out) },
    }
}

#[target_feature(enable = "avx512f,avx512vl,avx2")]
fn sum_avx512(args: (&Local<'_>, &[Vec3], &Stream, usize), out: &mut [Block]) {
    // SAFETY: this function has AVX-512's instructions.
    unsafe { sum_in::<__m512d>(args, out) }
}

#[target_feature(enable = "avx2")]
fn sum_avx2(args: (&Local<'_>, &[Vec3], &Stream, usize), out: &mut [Block]) {
    // SAFETY: this function has AVX2's instructions.
    unsafe { sum_in::<__m256d>(args, out) }
}

/// `Local::inertia` then `Local::springs`, operation for operation, `V::WIDTH` particles
/// at a time.
#[inline(always)]
unsafe fn sum_in<V: Wide>(
    (local, x, stream, block): (&Local<'_>, &[Vec3], &Stream, usize),
    out: &mut [Block],
) {
    let dt = local.dt;
    let model = local.model;
    let xs = x.as_ptr() as *const f64;
    let starts = local.start.as_ptr() as *const f64;
    let targets = local.target.as_ptr() as *const f64;
    let (first, rows) = stream.blocks[block];
    let own = &stream.own[block];
    let mass: Row = std::array::from_fn(|l| local.mass[own[l] as usize / 3]);
    // The model's drag coefficient per lane, by its own rule; divided by `dt` in the lanes.
    let drag_on: Row = mass.map(|m| model.drag_on(m));
    let mut f_out = [[0.0; LANES]; 3];
    let mut h_out = [[0.0; LANES]; 6];
    // SAFETY: every index in the stream is a coordinate of a particle of `x` (whose length
    // `local.start` and `local.target` share), and every lane range is within `LANES`.
    unsafe {
        let (zero, one) = (V::splat(0.0), V::splat(1.0));
        let (dtv, dt2) = (V::splat(dt), V::splat(dt * dt));
        let degenerate = V::splat(crate::forces::spring::DEGENERATE_LENGTH);
        for base in (0..LANES).step_by(V::WIDTH) {
            let own_index = own[base..].as_ptr();
            let xi = each!(c => V::gather(xs.add(c), own_index));
            let si = each!(c => V::gather(starts.add(c), own_index));
            let ti = each!(c => V::gather(targets.add(c), own_index));
            let m = V::load(mass[base..].as_ptr());
            let inertia = m.div(dt2);
            let moved = each!(c => xi[c].sub(si[c]));
            let mut f = each!(c => ti[c].sub(xi[c]).mul(inertia));
            let diagonal = zero.add(inertia);
            let mut h = [diagonal, diagonal, diagonal, zero, zero, zero];
            if model.has_drag() {
                let drag = V::load(drag_on[base..].as_ptr()).div(dtv);
                for c in 0..3 {
                    f[c] = f[c].sub(moved[c].mul(drag));
                    h[c] = h[c].add(drag);
                }
            }
            let counts = V::load(stream.counts[block][base..].as_ptr());
            for r in 0..rows as usize {
                let row = first as usize + r;
                let other = stream.other[row][base..].as_ptr();
                let rest = V::load(stream.rest[row][base..].as_ptr());
                let ks = V::load(stream.ks[row][base..].as_ptr());
                let kd = V::load(stream.kd[row][base..].as_ptr());
                // `kd / dt` here rather than kept per row: a division in the shadow of the
                // gathers, and a fifth of the rows' memory.
                let kd_dt = kd.div(dtv);
                let xj = each!(c => V::gather(xs.add(c), other));
                let sj = each!(c => V::gather(starts.add(c), other));
                let d = each!(c => xi[c].sub(xj[c]));
                let len = zero
                    .add(d[0].mul(d[0]).add(d[1].mul(d[1])).add(d[2].mul(d[2])))
                    .sqrt();
                let on = V::and(V::splat(r as f64).lt(counts), len.not_lt(degenerate));
                let u = each!(c => d[c].div(len));
                // `(moved - (x_j - start_j)) · u / dt`, nalgebra's dot: `(a + b) + c`.
                let rel = each!(c => moved[c].sub(xj[c].sub(sj[c])));
                let rate = rel[0]
                    .mul(u[0])
                    .add(rel[1].mul(u[1]))
                    .add(rel[2].mul(u[2]))
                    .div(dtv);
                let pull = ks.mul(len.sub(rest)).add(kd.mul(rate));
                for c in 0..3 {
                    f[c] = V::select(on, f[c].sub(u[c].mul(pull)), f[c]);
                }
                let t = one.sub(rest.div(len));
                let transverse = V::select(t.gt(zero), t, zero);
                let along = ks.mul(one.sub(transverse)).add(kd_dt);
                let across = ks.mul(transverse);
                // `Sym3::outer(u).scale(along).plus_identity(across)`, then added.
                const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
                for (k, (a, b)) in PAIRS.into_iter().enumerate() {
                    let mut term = u[a].mul(u[b]).mul(along);
                    if k < 3 {
                        term = term.add(across);
                    }
                    h[k] = V::select(on, h[k].add(term), h[k]);
                }
            }
            for c in 0..3 {
                f[c].store(f_out[c][base..].as_mut_ptr());
            }
            for k in 0..6 {
                h[k].store(h_out[k][base..].as_mut_ptr());
            }
        }
    }
    for (l, o) in out.iter_mut().enumerate() {
        *o = Block {
            f: Vec3::new(f_out[0][l], f_out[1][l], f_out[2][l]),
            h: Sym3(std::array::from_fn(|k| h_out[k][l])),
        };
    }
}
