//! Which batch layout the AVX-512 per-spring loop uses, and how many springs its run loop
//! takes per group, each chosen by timing both on this CPU.
//!
//! The two layouts (see `crate::forces::spring`) give the same bits, but which is faster depends
//! on the microarchitecture, by more than a rule on the instruction set can capture:
//! `VectorBatch` ran cloth-256 7 % faster than `ComponentBatch` on a Zen 5, while on a Zen 4
//! it made a `jello.w` RK4 step 40 % slower (median 150 µs against 104 µs, 2 threads).
//! So the first AVX-512 scatter of a process times both on a small mesh-like system and
//! keeps the faster for the rest of the process. The run loop's groups likewise: eight
//! springs in 512-bit registers or four in 256-bit ones, which on an Intel Xeon with
//! AVX-512 ran cloth-1024 about 5 % faster (two 256-bit operations issue where one 512-bit
//! one does, and the square root and division cost no more per lane). The per-spring loop
//! is timed compiled for AVX2 too (component batches in 256-bit registers): on the same
//! Xeon it ran a `jello.w` RK4 step 15 % faster than either AVX-512 layout (7.55k against
//! 6.5k steps/s on one thread). The choices change speed, never a result.

use super::force_loop::ScatterArgs;
use super::run_loop::{Run, RunArgs};
use crate::particles::Vec3;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// How a batch of the per-spring loop holds its springs' vectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BatchLayout {
    /// One array per component ([`ComponentBatch`]).
    Component,
    /// Each vector whole ([`VectorBatch`]).
    Vector,
    /// One array per component, in the AVX2 kernel's loop (256-bit registers).
    Narrow,
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

/// A deterministic stream of numbers in `[0, 1)` (xorshift64 from `seed`, which must not
/// be zero): the timed systems' jitter, and the test systems'.
pub(crate) fn unit_numbers(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Which of `N` ways of doing one job is the fastest, `pass(k)` timing way `k`: nine
/// interleaved rounds and the best of each, as a neighbour's burst slows some passes of
/// all, not all of one. Ties go to the earlier way.
fn fastest<const N: usize>(mut pass: impl FnMut(usize) -> Duration) -> usize {
    let mut best = [Duration::MAX; N];
    for _ in 0..9 {
        for (k, best) in best.iter_mut().enumerate() {
            *best = (*best).min(pass(k));
        }
    }
    (0..N).min_by_key(|&k| best[k]).unwrap_or(0)
}

/// Times the three layouts and returns the one with the fastest best pass.
#[allow(unsafe_code)]
unsafe fn faster_layout() -> BatchLayout {
    let mut next = unit_numbers(0x2545_f491_4f6c_dd1d);
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
    const LAYOUTS: [BatchLayout; 3] = [
        BatchLayout::Component,
        BatchLayout::Vector,
        BatchLayout::Narrow,
    ];
    let pass = |k: usize| {
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
        unsafe { super::scatter_avx512_in::<true, &[f64]>(LAYOUTS[k], args) };
        start.elapsed()
    };
    LAYOUTS[fastest::<3>(pass)]
}

/// How many springs the AVX-512 run loop computes per group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum RunWidth {
    /// Eight, in 512-bit registers.
    Eight,
    /// Four, in 256-bit registers (the AVX2 kernel's group).
    Four,
}

/// The run loop's group width in this process: measured on first use.
///
/// # Safety
/// The CPU must support AVX-512F, AVX-512VL and AVX2 (`super::Kernel::detect`).
#[allow(unsafe_code)]
pub(crate) unsafe fn avx512_run_width() -> RunWidth {
    static CHOICE: OnceLock<RunWidth> = OnceLock::new();
    // SAFETY: passed on from the caller.
    *CHOICE.get_or_init(|| unsafe { faster_run_width() })
}

/// The timed grid: rows of this many particles, and as many rows.
const SIDE: usize = 64;

/// A `SIDE × SIDE` cloth's structural, shear and bend springs as the layout hands them to
/// the run loop (24k springs, all in L2): cut at chunks of lower ends, by chunk and then by
/// offset from the largest, with their rest lengths; and its particles' positions and
/// velocities, jittered by `seed`.
fn run_grid(seed: u64) -> RunGrid {
    use super::run_loop::RUN_CHUNK;
    let n = SIDE * SIDE;
    let mut next = unit_numbers(seed | 1);
    let x: Vec<Vec3> = (0..n)
        .map(|p| Vec3::new((p % SIDE) as f64 + next(), (p / SIDE) as f64, next()) * 0.1)
        .collect();
    let v: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next())).collect();
    let offsets = [2 * SIDE, SIDE + 1, SIDE, SIDE - 1, 2, 1];
    let mut runs = Vec::new();
    for lo in (0..n - 2 * SIDE - RUN_CHUNK).step_by(RUN_CHUNK) {
        for offset in offsets {
            runs.push(Run {
                lo: lo as u32,
                offset: offset as u32,
                len: RUN_CHUNK as u32,
                first: (runs.len() * RUN_CHUNK) as u32,
                same_rest: true,
            });
        }
    }
    let rest = vec![0.1; runs.len() * RUN_CHUNK];
    RunGrid { runs, rest, x, v }
}

/// [`run_grid`]'s system.
struct RunGrid {
    runs: Vec<Run>,
    rest: Vec<f64>,
    x: Vec<Vec3>,
    v: Vec<Vec3>,
}

/// The run loop over `grid` with groups of `width`, into `force` (by component, thirds of
/// equal length).
///
/// # Safety
/// The CPU must support AVX-512F, AVX-512VL and AVX2.
#[allow(unsafe_code)]
unsafe fn run_pass(width: RunWidth, grid: &RunGrid, force: &mut [f64]) {
    let n = grid.x.len();
    let (fx, fyz) = force.split_at_mut(n);
    let (fy, fz) = fyz.split_at_mut(n);
    let args = RunArgs {
        springs: &grid.runs,
        rest: &grid.rest[..],
        param: &[],
        params: &[[1000.0, 0.01]],
        lo: 0,
        force: [fx, fy, fz],
        x: &grid.x,
        v: &grid.v,
    };
    // SAFETY: passed on from the caller.
    unsafe {
        match width {
            RunWidth::Eight => super::runs_avx512_eight::<true, &[f64]>(args),
            RunWidth::Four => super::runs_avx2::<true, &[f64]>(args),
        }
    }
}

/// Times both group widths on [`run_grid`] and returns the one with the faster best pass.
#[allow(unsafe_code)]
unsafe fn faster_run_width() -> RunWidth {
    let grid = run_grid(1);
    let mut force = vec![0.0; 3 * grid.x.len()];
    let pass = |k: usize| {
        let width = [RunWidth::Eight, RunWidth::Four][k];
        let start = Instant::now();
        // SAFETY: passed on from the caller.
        unsafe { run_pass(width, &grid, &mut force) };
        start.elapsed()
    };
    [RunWidth::Eight, RunWidth::Four][fastest::<2>(pass)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both group widths of the AVX-512 run loop give the same bits, whichever this
    /// process chose (on a CPU without AVX-512 there is nothing to compare).
    #[test]
    #[allow(unsafe_code)]
    fn both_run_widths_give_the_same_bits() {
        if super::super::Kernel::detect() < super::super::Kernel::Avx512 {
            return;
        }
        for seed in [3, 17] {
            let grid = run_grid(seed);
            let forces = |width| {
                let mut force = vec![0.0; 3 * grid.x.len()];
                // SAFETY: the CPU has AVX-512 (checked above).
                unsafe { run_pass(width, &grid, &mut force) };
                force.iter().map(|f| f.to_bits()).collect::<Vec<u64>>()
            };
            let eight = forces(RunWidth::Eight);
            assert!(eight.iter().any(|&f| f != 0), "the springs pull");
            assert!(eight == forces(RunWidth::Four), "seed {seed}");
        }
    }
}
