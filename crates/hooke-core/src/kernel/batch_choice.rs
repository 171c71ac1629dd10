//! Which batch layout the AVX-512 per-spring loop uses, chosen by timing both on this CPU.
//!
//! The two layouts (see `crate::spring`) give the same bits, but which is faster depends
//! on the microarchitecture, by more than a rule on the instruction set can capture:
//! `VectorBatch` ran cloth-256 7 % faster than `ComponentBatch` on a Zen 5, while on a Zen 4
//! it made a `jello.w` RK4 step 40 % slower (median 150 µs against 104 µs, 2 threads).
//! So the first AVX-512 scatter of a process times both on a small mesh-like system and
//! keeps the faster for the rest of the process. The choice changes speed, never a result.

use super::force_loop::{LANES, ScatterArgs, scatter_springs};
use crate::particles::Vec3;
use crate::spring::{ComponentBatch, SpringBatch, VectorBatch};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// How a batch of the per-spring loop holds its springs' vectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BatchLayout {
    /// One array per component ([`ComponentBatch`]).
    Component,
    /// Each vector whole ([`VectorBatch`]).
    Vector,
}

/// The layout the AVX-512 loop uses in this process: measured on first use.
///
/// # Safety
/// The CPU must support AVX-512F, AVX-512VL and AVX2 (`super::Kernel::detect`).
#[allow(unsafe_code)]
pub(crate) unsafe fn avx512_layout() -> BatchLayout {
    static CHOICE: OnceLock<BatchLayout> = OnceLock::new();
    // SAFETY: passed on from the caller.
    *CHOICE.get_or_init(|| unsafe { faster_layout() })
}

/// Particles and neighbours per particle of the timed system: 4k springs, about a jelly
/// cube's count and a thirtieth of a millisecond per pass, all in L1 and L2 so that the
/// loop's own cost is what is timed.
const PARTICLES: usize = 512;
const OFFSETS: [u32; 8] = [1, 2, 7, 8, 9, 16, 63, 64];

/// Times both layouts, interleaved, and returns the one with the faster best pass.
#[allow(unsafe_code)]
unsafe fn faster_layout() -> BatchLayout {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let x: Vec<Vec3> = (0..PARTICLES)
        .map(|p| Vec3::new(p as f64 * 0.1 + next(), next(), next()))
        .collect();
    let v: Vec<Vec3> = (0..PARTICLES)
        .map(|_| Vec3::new(next(), next(), next()))
        .collect();
    let ends: Vec<[u32; 2]> = (0..PARTICLES as u32)
        .flat_map(|i| OFFSETS.iter().map(move |d| [i, i + d]))
        .filter(|&[_, j]| (j as usize) < PARTICLES)
        .collect();
    let rest = vec![0.1; ends.len()];
    let mut force = vec![Vec3::zeros(); PARTICLES];
    let mut pass = |layout: BatchLayout| {
        let args = ScatterArgs {
            springs: &ends[..],
            rest: &rest[..],
            param: &[],
            params: &[[1000.0, 0.01]],
            lo: 0,
            force: &mut force[..],
            x: &x,
            v: &v,
        };
        let start = Instant::now();
        // SAFETY: passed on from the caller.
        unsafe {
            match layout {
                BatchLayout::Component => timed::<ComponentBatch<LANES>>(args),
                BatchLayout::Vector => timed::<VectorBatch<LANES>>(args),
            }
        }
        start.elapsed()
    };
    let mut best = [Duration::MAX; 2];
    // Interleaved rounds and the best of each: a neighbour's burst slows some passes of
    // both, not all of one.
    for _ in 0..9 {
        best[0] = best[0].min(pass(BatchLayout::Component));
        best[1] = best[1].min(pass(BatchLayout::Vector));
    }
    if best[1] < best[0] {
        BatchLayout::Vector
    } else {
        BatchLayout::Component
    }
}

/// The per-spring loop compiled for AVX-512 with batch layout `B`.
#[target_feature(enable = "avx512f,avx512vl,avx2")]
fn timed<B: SpringBatch<LANES>>(args: ScatterArgs<&[f64]>) {
    scatter_springs::<true, &[f64], B>(args);
}
