//! The force loop's compilations for the instruction sets of the CPU it runs on.
//!
//! The spring forces are the solver's hot loop, and their cost is a square root and a
//! division per spring, whose throughput per instruction is the same for 1, 2, 4 or 8
//! lanes on current x86 cores: wider vectors are nearly free speed. Portable builds target
//! baseline x86-64 (2 lanes), so the loop is compiled again for AVX2 and AVX-512 and the
//! widest the CPU supports is picked at run time. Portable and AVX2 builds batch springs
//! by component (`ComponentBatch`, see `spring.rs`); the AVX-512 build times both layouts
//! and the AVX2 loop once per process and keeps the fastest (`batch_choice.rs`). The
//! symplectic update of particles moved by springs and gravity alone is compiled per
//! kernel too (`advance.rs`).
//! Its `unsafe` is calling functions compiled for features that were checked to be
//! present (the one other use in the workspace is the one-pass step's shared state,
//! `assembly/fused.rs`).

mod advance;
mod batch_choice;
mod force_loop;
mod run_avx2;
mod run_avx512;
mod run_loop;

pub(crate) use advance::Advance;
pub(crate) use batch_choice::BatchLayout;
#[cfg(target_arch = "x86_64")]
use batch_choice::RunWidth;
#[cfg(test)]
pub(crate) use batch_choice::unit_numbers;
pub(crate) use force_loop::{RestLookup, ScatterArgs, Window};
pub(crate) use run_loop::{MAX_OFFSETS, RUN_CHUNK, Run, RunArgs};

use crate::forces::spring::{ComponentBatch, VectorBatch};
use crate::particles::Vec3;
use force_loop::{LANES, scatter_springs};
use run_loop::{GROUP, group_by_lane, scatter_runs};
use std::fmt;
use std::str::FromStr;

/// Which compilation of the force loop runs. The same code is compiled for each
/// instruction set, and without fused multiply-adds (Rust never contracts `a * b + c`),
/// each lane does the same correctly rounded operations in the same order: every kernel
/// gives the same bits, as a test checks. Wider vectors pay where a spring's cost is, its
/// square root and division, whose throughput per instruction does not depend on the
/// width on current x86 cores. Kernels are ordered narrowest first.
///
/// ```
/// use hooke_core::Kernel;
/// // Every CPU runs the portable loop; the widest available one is the default.
/// assert_eq!(Kernel::available()[0], Kernel::Portable);
/// assert!(Kernel::detect() >= Kernel::Portable);
/// assert_eq!("avx512".parse::<Kernel>(), Ok(Kernel::Avx512));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kernel {
    /// Baseline x86-64 (SSE2), or whatever the target compiles for elsewhere.
    #[default]
    Portable,
    /// AVX2: four springs per instruction.
    Avx2,
    /// AVX-512: eight springs per instruction.
    Avx512,
}

impl Kernel {
    /// The widest kernel this CPU runs.
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl")
                && std::arch::is_x86_feature_detected!("avx2")
            {
                return Self::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                return Self::Avx2;
            }
        }
        Self::Portable
    }

    /// Every kernel this CPU runs, narrowest first.
    pub fn available() -> Vec<Self> {
        Self::ALL
            .into_iter()
            .filter(|k| *k <= Self::detect())
            .collect()
    }

    /// Every kernel, narrowest first.
    pub const ALL: [Kernel; 3] = [Self::Portable, Self::Avx2, Self::Avx512];

    /// The lowercase name shown by benchmarks.
    pub fn name(self) -> &'static str {
        match self {
            Self::Portable => "portable",
            Self::Avx2 => "avx2",
            Self::Avx512 => "avx512",
        }
    }

    /// How many springs this kernel's run loop computes per group: 4 for the portable
    /// kernel (lane by lane) and AVX2, and 8 or 4 for AVX-512, which times both once per
    /// process on first use and keeps the faster. Both give the same bits.
    #[allow(unsafe_code)]
    pub fn run_lanes(self) -> usize {
        match self.min(Self::detect()) {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the kernel is at most `detect()`, which checked AVX-512's features.
            Self::Avx512 => match unsafe { batch_choice::avx512_run_width() } {
                RunWidth::Eight => 8,
                RunWidth::Four => 4,
            },
            _ => GROUP,
        }
    }

    /// How this kernel's per-spring loop batches springs: `"component"` (one array per
    /// component), `"vector"` (each vector whole) or `"256-bit component"` (the AVX2
    /// kernel's loop). The AVX-512 kernel times the three once per process on first use and
    /// keeps the fastest; the others always batch by component. All give the same bits.
    #[allow(unsafe_code)]
    pub fn batches(self) -> &'static str {
        let layout = match self.min(Self::detect()) {
            // SAFETY: the kernel is at most `detect()`, which checked AVX-512's features.
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 => unsafe { batch_choice::avx512_layout() },
            _ => BatchLayout::Component,
        };
        match layout {
            BatchLayout::Component => "component",
            BatchLayout::Vector => "vector",
            BatchLayout::Narrow => "256-bit component",
        }
    }

    /// Runs the spring force loop compiled for this kernel.
    #[allow(unsafe_code)]
    pub(crate) fn scatter<const UNIFORM: bool, R: RestLookup>(self, args: ScatterArgs<R>) {
        // Anyone can name a kernel; only one the CPU has runs (std caches the detection,
        // so this is a few loads per call of a loop over thousands of springs).
        match self.min(Self::detect()) {
            Self::Portable => scatter_springs::<UNIFORM, R, ComponentBatch<LANES>>(args),
            // SAFETY: the kernel is at most `detect()`, which checked that the CPU has every
            // feature these functions are compiled for (and they enable nothing else).
            #[cfg(target_arch = "x86_64")]
            Self::Avx2 => unsafe { scatter_avx2::<UNIFORM, R>(args) },
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 => unsafe {
                scatter_avx512_in::<UNIFORM, R>(batch_choice::avx512_layout(), args)
            },
            #[cfg(not(target_arch = "x86_64"))]
            _ => scatter_springs::<UNIFORM, R, ComponentBatch<LANES>>(args),
        }
    }

    /// [`Kernel::scatter`] with the AVX-512 loop's batch layout given, for tests of each.
    #[cfg(test)]
    #[allow(unsafe_code)]
    pub(crate) fn scatter_with<const UNIFORM: bool, R: RestLookup>(
        self,
        layout: BatchLayout,
        args: ScatterArgs<R>,
    ) {
        match self.min(Self::detect()) {
            // SAFETY: as in `scatter`.
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 => unsafe { scatter_avx512_in::<UNIFORM, R>(layout, args) },
            other => other.scatter::<UNIFORM, R>(args),
        }
    }
}

impl Kernel {
    /// Runs the force loop over runs of springs compiled for this kernel.
    #[allow(unsafe_code)]
    pub(crate) fn scatter_runs<const UNIFORM: bool, R: RestLookup>(self, args: RunArgs<R>) {
        match self.min(Self::detect()) {
            Self::Portable => scatter_runs::<UNIFORM, R, GROUP>(args, group_by_lane),
            // SAFETY: as in `scatter`.
            #[cfg(target_arch = "x86_64")]
            Self::Avx2 => unsafe { runs_avx2::<UNIFORM, R>(args) },
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 => unsafe {
                match batch_choice::avx512_run_width() {
                    RunWidth::Eight => runs_avx512_eight::<UNIFORM, R>(args),
                    RunWidth::Four => runs_avx2::<UNIFORM, R>(args),
                }
            },
            #[cfg(not(target_arch = "x86_64"))]
            _ => scatter_runs::<UNIFORM, R, GROUP>(args, group_by_lane),
        }
    }
}

impl Kernel {
    /// Runs the symplectic update of particles moved by springs (`springs`, their forces)
    /// and gravity alone compiled for this kernel (see `advance.rs`): updates `x` and `v`
    /// in place and returns whether the new state is sane.
    #[allow(unsafe_code)]
    pub(crate) fn advance(
        self,
        a: &Advance,
        springs: &[Vec3],
        x: &mut [Vec3],
        v: &mut [Vec3],
    ) -> bool {
        match self.min(Self::detect()) {
            Self::Portable => advance::advance_portable(a, springs, x, v),
            // SAFETY: as in `scatter`.
            #[cfg(target_arch = "x86_64")]
            Self::Avx2 => unsafe { advance::advance_avx2(a, springs, x, v) },
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 => unsafe { advance::advance_avx512(a, springs, x, v) },
            #[cfg(not(target_arch = "x86_64"))]
            _ => advance::advance_portable(a, springs, x, v),
        }
    }
}

impl fmt::Display for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The error for a kernel name that is not one of [`Kernel::ALL`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown kernel '{0}': expected one of portable, avx2, avx512")]
pub struct UnknownKernel(pub String);

impl FromStr for Kernel {
    type Err = UnknownKernel;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| UnknownKernel(s.to_string()))
    }
}

/// The spring force loop compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(crate) fn scatter_avx2<const UNIFORM: bool, R: RestLookup>(args: ScatterArgs<R>) {
    scatter_springs::<UNIFORM, R, ComponentBatch<LANES>>(args);
}

/// The AVX-512 kernel's per-spring loop in `layout`: the AVX2 compilation for
/// [`BatchLayout::Narrow`], called from here and not from an AVX-512 function, which could
/// inline it and compile it for AVX-512 after all.
///
/// # Safety
/// The CPU must support AVX-512F, AVX-512VL and AVX2.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
pub(crate) unsafe fn scatter_avx512_in<const UNIFORM: bool, R: RestLookup>(
    layout: BatchLayout,
    args: ScatterArgs<R>,
) {
    // SAFETY: passed on from the caller.
    unsafe {
        match layout {
            BatchLayout::Narrow => scatter_avx2::<UNIFORM, R>(args),
            _ => scatter_avx512::<UNIFORM, R>(layout, args),
        }
    }
}

/// The spring force loop compiled for AVX-512, with batches in `layout` (component batches
/// for [`BatchLayout::Narrow`], which `scatter_avx512_in` sends elsewhere).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx2")]
fn scatter_avx512<const UNIFORM: bool, R: RestLookup>(layout: BatchLayout, args: ScatterArgs<R>) {
    match layout {
        BatchLayout::Component | BatchLayout::Narrow => {
            scatter_springs::<UNIFORM, R, ComponentBatch<LANES>>(args)
        }
        BatchLayout::Vector => scatter_springs::<UNIFORM, R, VectorBatch<LANES>>(args),
    }
}

/// The run loop compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(crate) fn runs_avx2<const UNIFORM: bool, R: RestLookup>(args: RunArgs<R>) {
    scatter_runs::<UNIFORM, R, GROUP>(args, |g| run_avx2::group_avx2(g));
}

/// The run loop compiled for AVX-512, eight springs per group.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx2")]
pub(crate) fn runs_avx512_eight<const UNIFORM: bool, R: RestLookup>(args: RunArgs<R>) {
    scatter_runs::<UNIFORM, R, { run_avx512::WIDE }>(args, |g| run_avx512::group_avx512(g));
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::assembly::Assembly;
    use crate::forces::spring::{Spring, SpringKind};
    use crate::particles::Vec3;

    /// Each vector's components as bits, for comparing results to the bit.
    pub(crate) fn bits(a: &[Vec3]) -> Vec<[u64; 3]> {
        a.iter().map(|f| f.map(f64::to_bits).into()).collect()
    }

    /// A rayon pool of `threads` threads.
    pub(crate) fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
    }

    /// A deterministic jumble of particles and `count` springs: random ends, lengths from 0
    /// (a degenerate spring) to far stretched, and several `(ks, kd)` pairs or just one.
    pub(crate) fn jumble(uniform: bool, count: usize) -> (Vec<Vec3>, Vec<Vec3>, Vec<Spring>) {
        let mut next = batch_choice::unit_numbers(0x2545_f491_4f6c_dd1d);
        let n = 3000;
        let mut x: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next())).collect();
        x[1] = x[0];
        let v: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(next(), next(), next()) * 0.1)
            .collect();
        let mut springs = vec![Spring {
            i: 0,
            j: 1,
            rest: 0.5,
            ks: 100.0,
            kd: 0.5,
            kind: SpringKind::Other,
        }];
        for k in 0..count {
            let i = (next() * n as f64) as u32;
            // Mostly near neighbours, as in a mesh, sometimes anywhere.
            let j = if k % 7 == 0 {
                (next() * n as f64) as u32
            } else {
                (i + 1 + (next() * 40.0) as u32) % n as u32
            };
            if i == j {
                continue;
            }
            let (ks, kd) = if uniform {
                (100.0, 0.5)
            } else {
                (100.0 * (1 + k % 3) as f64, 0.25 * (k % 4) as f64)
            };
            springs.push(Spring {
                i,
                j,
                rest: next() * 0.3,
                ks,
                kd,
                kind: SpringKind::Other,
            });
        }
        (x, v, springs)
    }

    #[test]
    fn every_kernel_gives_the_same_bits() {
        // Rest lengths are stored per spring for 20k springs (a small system), indexed for
        // 40k (random lengths, all distinct), and per spring again for 70k (over 65536
        // distinct ones).
        let cases = [
            (true, 20_000),
            (false, 20_000),
            (false, 40_000),
            (true, 70_000),
        ];
        for (uniform, count) in cases {
            let (x, v, springs) = jumble(uniform, count);
            let forces = |kernel: Kernel| {
                let mut asm = Assembly::new(x.len(), &springs);
                assert_eq!(asm.rest_indexed(), count == 40_000, "{count} springs");
                asm.set_kernel(kernel);
                assert_eq!(asm.kernel(), kernel);
                asm.scatter(&x, &v);
                let mut f = vec![Vec3::zeros(); x.len()];
                asm.map_gathered(&mut f, |_, sum| sum);
                f
            };
            let portable = forces(Kernel::Portable);
            // The layout sums the same forces as a naive loop over the springs, in another
            // order: equal up to round-off.
            let mut naive = vec![Vec3::zeros(); x.len()];
            for s in &springs {
                let (i, j) = (s.i as usize, s.j as usize);
                let f = s.force(&x[i], &x[j], &v[i], &v[j]);
                naive[i] += f;
                naive[j] -= f;
            }
            for (p, (a, b)) in portable.iter().zip(&naive).enumerate() {
                assert!(
                    (a - b).norm() <= 1e-9 * (1.0 + b.norm()),
                    "particle {p}: {a} vs {b}"
                );
            }
            for kernel in Kernel::available() {
                let f = forces(kernel);
                let same = f.iter().zip(&portable).all(|(a, b)| {
                    a.iter()
                        .zip(b.iter())
                        .all(|(a, b)| a.to_bits() == b.to_bits())
                });
                assert!(
                    same,
                    "{kernel} differs from portable ({count}, uniform: {uniform})"
                );
            }
        }
    }

    #[test]
    fn both_avx512_batch_layouts_give_the_portable_bits() {
        // The process keeps one layout, timed on this CPU: each is run here by name. On a
        // CPU without AVX-512 both runs are the widest kernel it has.
        let (x, v, springs) = jumble(false, 20_000);
        let mut ends: Vec<[u32; 2]> = springs
            .iter()
            .map(|s| [s.i.min(s.j), s.i.max(s.j)])
            .collect();
        ends.sort();
        let rest: Vec<f64> = springs.iter().map(|s| s.rest).collect();
        let params: Vec<[f64; 2]> = vec![[100.0, 0.25], [200.0, 0.5], [300.0, 0.0]];
        let param: Vec<u32> = (0..ends.len() as u32).map(|k| k % 3).collect();
        let forces = |kernel: Kernel, layout: BatchLayout| {
            let mut f = vec![Vec3::zeros(); x.len()];
            kernel.scatter_with::<false, _>(
                layout,
                ScatterArgs {
                    springs: &ends[..],
                    rest: &rest[..],
                    param: &param,
                    params: &params,
                    lo: 0,
                    force: &mut f,
                    x: &x,
                    v: &v,
                },
            );
            f.iter()
                .flat_map(|f| f.iter().map(|c| c.to_bits()))
                .collect::<Vec<u64>>()
        };
        let portable = forces(Kernel::Portable, BatchLayout::Component);
        assert!(portable.iter().any(|&b| b != 0), "the springs pull");
        let layouts = [
            BatchLayout::Component,
            BatchLayout::Vector,
            BatchLayout::Narrow,
        ];
        for layout in layouts {
            assert!(forces(Kernel::Avx512, layout) == portable, "{layout:?}");
        }
    }

    /// The springs of an `a × b × c` lattice numbered row by row (`c` fastest): every
    /// neighbour within distance 2 along each axis and the face and body diagonals, as a
    /// cloth (`a = 1`) or a jelly cube has, with `extra` springs between random particles
    /// and, unless `uniform`, stiffness and damping by kind.
    pub(crate) fn lattice(
        [a, b, c]: [usize; 3],
        extra: usize,
        uniform: bool,
    ) -> (Vec<Vec3>, Vec<Vec3>, Vec<Spring>) {
        let id = |i: usize, j: usize, k: usize| (i * b + j) * c + k;
        let mut next = batch_choice::unit_numbers(0x853c_49e6_748f_ea9b);
        let mut x = vec![Vec3::zeros(); a * b * c];
        let mut v = x.clone();
        for i in 0..a {
            for j in 0..b {
                for k in 0..c {
                    let jitter = Vec3::new(next(), next(), next()) * 0.01;
                    x[id(i, j, k)] = Vec3::new(i as f64, j as f64, k as f64) * 0.1 + jitter;
                    v[id(i, j, k)] = Vec3::new(next(), next(), next()) - Vec3::repeat(0.5);
                }
            }
        }
        let mut springs = Vec::new();
        let mut add = |p: usize, q: usize, kind: usize, x: &[Vec3]| {
            let (ks, kd) = if uniform {
                (1000.0, 0.01)
            } else {
                (500.0 * (1 + kind) as f64, 0.1 * kind as f64)
            };
            springs.push(Spring {
                i: p as u32,
                j: q as u32,
                rest: (x[p] - x[q]).norm() * 0.9,
                ks,
                kd,
                kind: SpringKind::Other,
            });
        };
        for i in 0..a {
            for j in 0..b {
                for k in 0..c {
                    for di in 0..=2usize {
                        for dj in 0..=2usize {
                            for dk in 0..=2usize {
                                let steps = [di, dj, dk];
                                let twos = steps.iter().filter(|&&s| s == 2).count();
                                let ones = steps.iter().filter(|&&s| s == 1).count();
                                // Bend (one axis, two steps) or structural and diagonals.
                                let keep = (twos == 1 && ones == 0) || (twos == 0 && ones > 0);
                                if keep && i + di < a && j + dj < b && k + dk < c {
                                    add(
                                        id(i, j, k),
                                        id(i + di, j + dj, k + dk),
                                        ones + 2 * twos,
                                        &x,
                                    );
                                }
                                // The other diagonals of a face or the cube.
                                if twos == 0
                                    && ones >= 2
                                    && dk == 1
                                    && k >= 1
                                    && i + di < a
                                    && j + dj < b
                                {
                                    add(id(i, j, k), id(i + di, j + dj, k - dk), ones, &x);
                                }
                            }
                        }
                    }
                }
            }
        }
        let n = x.len();
        for _ in 0..extra {
            let (p, q) = ((next() * n as f64) as usize, (next() * n as f64) as usize);
            if p != q {
                add(p, q, 3, &x);
            }
        }
        (x, v, springs)
    }

    #[test]
    fn runs_give_the_bits_of_the_per_spring_loop() {
        // A cloth whose rows do not fill whole chunks, a jelly cube, and a cloth with
        // springs that break its regularity in places; with one and several partitions.
        let cases = [
            ([1, 45, 37], 0, true),
            ([1, 45, 37], 0, false),
            ([8, 8, 8], 0, false),
            ([1, 70, 70], 40, true),
            ([1, 130, 129], 0, true),
        ];
        for (dims, extra, uniform) in cases {
            let (x, v, springs) = lattice(dims, extra, uniform);
            let forces = |runs: Option<usize>, kernel: Kernel| {
                let mut asm = Assembly::laid_out(x.len(), &springs, runs);
                asm.set_kernel(kernel);
                asm.scatter(&x, &v);
                let mut f = vec![Vec3::zeros(); x.len()];
                asm.map_gathered(&mut f, |_, sum| sum);
                (f, asm.springs_in_runs())
            };
            let (sorted, none) = forces(None, Kernel::Portable);
            assert_eq!(none, 0);
            for kernel in Kernel::available() {
                // Runs wherever they exist, however short.
                let (f, in_runs) = forces(Some(1), kernel);
                assert!(
                    in_runs * 10 >= springs.len() * 9,
                    "{dims:?}: only {in_runs} of {} springs in runs",
                    springs.len()
                );
                for (p, (a, b)) in f.iter().zip(&sorted).enumerate() {
                    assert!(
                        a.iter()
                            .zip(b.iter())
                            .all(|(a, b)| a.to_bits() == b.to_bits()),
                        "{dims:?} {kernel}, particle {p}: {a} with runs, {b} without"
                    );
                }
            }
        }
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for kernel in Kernel::ALL {
            assert_eq!(kernel.name().parse::<Kernel>(), Ok(kernel));
        }
        assert_eq!(
            "sse9".parse::<Kernel>().unwrap_err().to_string(),
            "unknown kernel 'sse9': expected one of portable, avx2, avx512"
        );
        assert!(Kernel::available().contains(&Kernel::Portable));
        assert_eq!(Kernel::available().last(), Some(&Kernel::detect()));
    }
}
