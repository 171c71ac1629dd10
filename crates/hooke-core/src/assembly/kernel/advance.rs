//! The symplectic Euler update of particles moved by springs and gravity alone, compiled
//! per kernel: `v' = v + (m g + f) / m dt`, `x' = x + v' dt`, pinned particles (inverse
//! mass 0) kept, and the new state checked for sanity.
//!
//! Done one particle at a time, the update cost a fifth of a cloth step: its components
//! sit in triples, which the compiler vectorises only two at a time, and the check ran as
//! a second pass. The vector kernels take the triples as they lie, eight or four particles
//! in three registers, and spread each particle's mass and inverse mass to its three lanes
//! with one permute, so nothing is transposed. Every lane does the portable loop's
//! operations in its order (no fused multiply-adds), so the bits are the same, as a test
//! checks.

use crate::particles::Vec3;

/// What moves the particles besides their springs, and the step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Advance<'a> {
    /// The particles' masses and inverse masses (0 for a pinned particle).
    pub mass: &'a [f64],
    pub inv_mass: &'a [f64],
    pub gravity: Vec3,
    pub dt: f64,
    /// The largest coordinate a sane position may have (velocities need only be finite).
    pub bound: f64,
}

/// The update lane by lane: what every kernel computes. Returns whether every particle's
/// new position is within the bound and its velocity finite (NaN is neither).
pub(crate) fn advance_portable(
    a: &Advance,
    springs: &[Vec3],
    x: &mut [Vec3],
    v: &mut [Vec3],
) -> bool {
    let n = springs.len();
    let (x, v) = (&mut x[..n], &mut v[..n]);
    let (mass, inv_mass) = (&a.mass[..n], &a.inv_mass[..n]);
    let mut ok = true;
    for k in 0..n {
        if inv_mass[k] != 0.0 {
            let f = a.gravity * mass[k] + springs[k];
            v[k] += f * inv_mass[k] * a.dt;
            x[k] += v[k] * a.dt;
        }
        let (p, u) = (x[k], v[k]);
        ok &= (p.x.abs() <= a.bound) & (p.y.abs() <= a.bound) & (p.z.abs() <= a.bound);
        ok &= u.x.is_finite() & u.y.is_finite() & u.z.is_finite();
    }
    ok
}

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::{advance_avx2, advance_avx512};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{Advance, advance_portable};
    use crate::particles::Vec3;
    use std::arch::x86_64::{
        __m256d, __m512d, __m512i, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_NEQ_UQ, _mm256_add_pd,
        _mm256_and_pd, _mm256_andnot_pd, _mm256_blendv_pd, _mm256_cmp_pd, _mm256_movemask_pd,
        _mm256_mul_pd, _mm256_permute4x64_pd, _mm256_set1_pd, _mm512_abs_pd, _mm512_add_pd,
        _mm512_cmp_pd_mask, _mm512_mask_mov_pd, _mm512_mul_pd, _mm512_permutexvar_pd,
        _mm512_set1_pd,
    };

    /// Runs `block(springs, x, v, mass, inv_mass)` on each whole block of `L` particles,
    /// their forces, positions and velocities as flat values, then the portable loop on the
    /// particles left; returns the portable loop's verdict.
    #[inline(always)]
    fn blocks<const L: usize>(
        a: &Advance,
        springs: &[Vec3],
        x: &mut [Vec3],
        v: &mut [Vec3],
        mut block: impl FnMut(&[f64], &mut [f64], &mut [f64], &[f64], &[f64]),
    ) -> bool {
        let wide = springs.len() / L * L;
        for k in (0..wide).step_by(L) {
            block(
                bytemuck::cast_slice(&springs[k..k + L]),
                bytemuck::cast_slice_mut(&mut x[k..k + L]),
                bytemuck::cast_slice_mut(&mut v[k..k + L]),
                &a.mass[k..k + L],
                &a.inv_mass[k..k + L],
            );
        }
        let rest = Advance {
            mass: &a.mass[wide..],
            inv_mass: &a.inv_mass[wide..],
            ..*a
        };
        advance_portable(&rest, &springs[wide..], &mut x[wide..], &mut v[wide..])
    }

    /// Particles per pass of the AVX-512 loop: their 24 coordinates fill three registers.
    const WIDE: usize = 8;

    /// For each of the three registers of eight particles' triples, the particle of each
    /// lane: the permute that spreads a particle's mass over its three coordinates.
    const SPREAD: [[i64; WIDE]; 3] = [
        [0, 0, 0, 1, 1, 1, 2, 2],
        [2, 3, 3, 3, 4, 4, 4, 5],
        [5, 5, 6, 6, 6, 7, 7, 7],
    ];

    /// The components of each lane of those registers: register `r` starts at component
    /// `(2 r) % 3`.
    fn components<const L: usize>(g: Vec3) -> [[f64; L]; 3] {
        std::array::from_fn(|r| std::array::from_fn(|l| g[(r * L + l) % 3]))
    }

    /// The update of eight particles at a time in AVX-512 registers, the rest lane by lane.
    #[target_feature(enable = "avx512f,avx512vl,avx2")]
    pub(crate) fn advance_avx512(
        a: &Advance,
        springs: &[Vec3],
        x: &mut [Vec3],
        v: &mut [Vec3],
    ) -> bool {
        let load = |v: &[f64]| -> __m512d {
            bytemuck::cast::<[f64; WIDE], _>(v.try_into().expect("eight"))
        };
        let gravity = components::<WIDE>(a.gravity).map(bytemuck::cast::<_, __m512d>);
        let spread = SPREAD.map(bytemuck::cast::<_, __m512i>);
        let (dt, bound) = (_mm512_set1_pd(a.dt), _mm512_set1_pd(a.bound));
        let (zero, infinity) = (_mm512_set1_pd(0.0), _mm512_set1_pd(f64::INFINITY));
        let mut ok = u8::MAX;
        let rest = blocks::<WIDE>(a, springs, x, v, |s, xs, vs, m, inv| {
            let (m, inv) = (load(m), load(inv));
            for r in 0..3 {
                let lanes = 8 * r..8 * r + 8;
                let (mr, ir) = (
                    _mm512_permutexvar_pd(spread[r], m),
                    _mm512_permutexvar_pd(spread[r], inv),
                );
                let moves = _mm512_cmp_pd_mask::<_CMP_NEQ_UQ>(ir, zero);
                let f = _mm512_add_pd(_mm512_mul_pd(gravity[r], mr), load(&s[lanes.clone()]));
                let (x0, v0) = (load(&xs[lanes.clone()]), load(&vs[lanes.clone()]));
                let v1 = _mm512_add_pd(v0, _mm512_mul_pd(_mm512_mul_pd(f, ir), dt));
                let x1 = _mm512_add_pd(x0, _mm512_mul_pd(v1, dt));
                let (x1, v1) = (
                    _mm512_mask_mov_pd(x0, moves, x1),
                    _mm512_mask_mov_pd(v0, moves, v1),
                );
                ok &= _mm512_cmp_pd_mask::<_CMP_LE_OQ>(_mm512_abs_pd(x1), bound)
                    & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(_mm512_abs_pd(v1), infinity);
                xs[lanes.clone()].copy_from_slice(&bytemuck::cast::<_, [f64; WIDE]>(x1));
                vs[lanes].copy_from_slice(&bytemuck::cast::<_, [f64; WIDE]>(v1));
            }
        });
        (ok == u8::MAX) & rest
    }

    /// Particles per pass of the AVX2 loop.
    const GROUP: usize = 4;

    /// Four particles' masses spread over their twelve coordinates, register by register.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn spread4(m: __m256d) -> [__m256d; 3] {
        [
            _mm256_permute4x64_pd::<0b01_00_00_00>(m),
            _mm256_permute4x64_pd::<0b10_10_01_01>(m),
            _mm256_permute4x64_pd::<0b11_11_11_10>(m),
        ]
    }

    /// The update of four particles at a time in AVX2 registers, the rest lane by lane.
    #[target_feature(enable = "avx2")]
    pub(crate) fn advance_avx2(
        a: &Advance,
        springs: &[Vec3],
        x: &mut [Vec3],
        v: &mut [Vec3],
    ) -> bool {
        let load = |v: &[f64]| -> __m256d {
            bytemuck::cast::<[f64; GROUP], _>(v.try_into().expect("four"))
        };
        let gravity = components::<GROUP>(a.gravity).map(bytemuck::cast::<_, __m256d>);
        let (dt, bound) = (_mm256_set1_pd(a.dt), _mm256_set1_pd(a.bound));
        let (zero, infinity) = (_mm256_set1_pd(0.0), _mm256_set1_pd(f64::INFINITY));
        let sign = _mm256_set1_pd(-0.0);
        let mut ok = _mm256_cmp_pd::<_CMP_LE_OQ>(zero, zero);
        let rest = blocks::<GROUP>(a, springs, x, v, |s, xs, vs, m, inv| {
            let (m, inv) = (spread4(load(m)), spread4(load(inv)));
            for r in 0..3 {
                let lanes = 4 * r..4 * r + 4;
                let moves = _mm256_cmp_pd::<_CMP_NEQ_UQ>(inv[r], zero);
                let f = _mm256_add_pd(_mm256_mul_pd(gravity[r], m[r]), load(&s[lanes.clone()]));
                let (x0, v0) = (load(&xs[lanes.clone()]), load(&vs[lanes.clone()]));
                let v1 = _mm256_add_pd(v0, _mm256_mul_pd(_mm256_mul_pd(f, inv[r]), dt));
                let x1 = _mm256_add_pd(x0, _mm256_mul_pd(v1, dt));
                let (x1, v1) = (
                    _mm256_blendv_pd(x0, x1, moves),
                    _mm256_blendv_pd(v0, v1, moves),
                );
                let within = _mm256_cmp_pd::<_CMP_LE_OQ>(_mm256_andnot_pd(sign, x1), bound);
                let finite = _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_andnot_pd(sign, v1), infinity);
                ok = _mm256_and_pd(ok, _mm256_and_pd(within, finite));
                xs[lanes.clone()].copy_from_slice(&bytemuck::cast::<_, [f64; GROUP]>(x1));
                vs[lanes].copy_from_slice(&bytemuck::cast::<_, [f64; GROUP]>(v1));
            }
        });
        (_mm256_movemask_pd(ok) == 0b1111) & rest
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::kernel::Kernel;
    use crate::assembly::kernel::tests::bits;
    use crate::assembly::kernel::unit_numbers;

    /// Every kernel the CPU runs updates to the portable loop's bits and verdict: with
    /// pinned particles, velocities of -0 (which `v + 0` would turn to +0 on a pinned one),
    /// a NaN force, a position pushed past the bound, and lengths that leave a tail for the
    /// lane-by-lane loop. The portable loop itself matches the formula written out.
    #[test]
    fn every_kernel_advances_to_the_portable_bits() {
        let mut next = unit_numbers(0x9e37_79b9_7f4a_7c15);
        let mut vec3 = |s: f64| Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * s;
        let n = 203;
        let springs: Vec<Vec3> = (0..n).map(|_| vec3(10.0)).collect();
        let x0: Vec<Vec3> = (0..n).map(|_| vec3(2.0)).collect();
        let mut v0: Vec<Vec3> = (0..n).map(|_| vec3(1.0)).collect();
        let mass: Vec<f64> = (0..n).map(|k| 0.01 * (1 + k % 5) as f64).collect();
        let mut inv_mass: Vec<f64> = mass.iter().map(|m| 1.0 / m).collect();
        for k in [0, 9, 64, 202] {
            inv_mass[k] = 0.0;
            v0[k] = Vec3::new(-0.0, 0.0, -0.0);
        }
        let advance = Advance {
            mass: &mass,
            inv_mass: &inv_mass,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            dt: 1e-3,
            bound: 1.0e6,
        };
        let mut insane = springs.clone();
        insane[77].y = f64::NAN;
        let mut far = springs.clone();
        far[150].x = 1.0e15;
        // Each case with the particle whose new state is not sane.
        let cases = [
            ("sane", &springs, None),
            ("NaN", &insane, Some(77)),
            ("far", &far, Some(150)),
        ];
        for (case, springs, bad) in cases {
            for len in [0, 1, 7, 8, 13, 64, n] {
                let run = |kernel: Kernel| {
                    let (mut x, mut v) = (x0[..len].to_vec(), v0[..len].to_vec());
                    let ok = kernel.advance(&advance, &springs[..len], &mut x, &mut v);
                    (bits(&x), bits(&v), ok)
                };
                let expected = run(Kernel::Portable);
                assert_eq!(expected.2, bad.is_none_or(|b| len <= b), "{case}, {len}");
                for kernel in Kernel::available() {
                    assert!(run(kernel) == expected, "{kernel}, {case}, {len} particles");
                }
            }
        }
        // The portable loop is the formula, and pinned particles keep every bit.
        let (mut x, mut v) = (x0.clone(), v0.clone());
        assert!(advance_portable(&advance, &springs, &mut x, &mut v));
        for k in 0..n {
            if inv_mass[k] == 0.0 {
                assert!(bits(&[x[k], v[k]]) == bits(&[x0[k], v0[k]]), "pinned {k}");
            } else {
                let f = advance.gravity * mass[k] + springs[k];
                let vk = v0[k] + f * inv_mass[k] * advance.dt;
                assert!(
                    bits(&[x[k], v[k]]) == bits(&[x0[k] + vk * advance.dt, vk]),
                    "{k}"
                );
            }
        }
    }
}
