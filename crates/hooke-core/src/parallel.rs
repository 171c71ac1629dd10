//! Splitting per-particle work across threads without changing a bit of the result.

use crate::particles::Vec3;
use rayon::prelude::*;

/// Runs `f` on a worker thread of the current rayon pool (the global one outside any
/// pool). A step makes several parallel calls; from a worker each is a cheap join, while
/// from any other thread each would inject its jobs into the pool and sleep until they
/// finish, which costs more than a small system's whole step. One hop per step or per
/// `advance` instead.
pub(crate) fn on_worker<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if rayon::current_thread_index().is_some() {
        f()
    } else {
        rayon::join(f, || ()).0
    }
}

/// Calls `f(start, a_block, b_block)` over matching blocks of `block` particles of two
/// per-particle arrays: in parallel when there is more than one block, inline otherwise
/// (a rayon call costs microseconds, too much for a 512-particle jelly stepped 10k times a
/// second). `start` is the block's first particle, for indexing arrays `f` only reads.
///
/// `f` must update each particle from that particle's own data, so the split into blocks
/// and threads cannot change the result.
pub(crate) fn for_blocks(
    block: usize,
    a: &mut [Vec3],
    b: &mut [Vec3],
    f: impl Fn(usize, &mut [Vec3], &mut [Vec3]) + Sync + Send,
) {
    if a.len() <= block {
        f(0, a, b);
    } else {
        a.par_chunks_mut(block)
            .zip(b.par_chunks_mut(block))
            .enumerate()
            .for_each(|(k, (a, b))| f(k * block, a, b));
    }
}

/// [`for_blocks`] with a third and a fourth per-particle array of any types (contact
/// flags, per-particle records), for updates that write four arrays in one pass.
pub(crate) fn for_blocks4<C: Send, D: Send>(
    block: usize,
    a: &mut [Vec3],
    b: &mut [Vec3],
    c: &mut [C],
    d: &mut [D],
    f: impl Fn(usize, &mut [Vec3], &mut [Vec3], &mut [C], &mut [D]) + Sync + Send,
) {
    if a.len() <= block {
        f(0, a, b, c, d);
    } else {
        a.par_chunks_mut(block)
            .zip(b.par_chunks_mut(block))
            .zip(c.par_chunks_mut(block))
            .zip(d.par_chunks_mut(block))
            .enumerate()
            .for_each(|(k, (((a, b), c), d))| f(k * block, a, b, c, d));
    }
}

/// [`for_blocks`] with a third per-particle array of any type, where `f` also reports
/// something about its block: whether every block
/// reported `true`. Every block runs, whatever the others report.
pub(crate) fn all_blocks3<C: Send>(
    block: usize,
    a: &mut [Vec3],
    b: &mut [Vec3],
    c: &mut [C],
    f: impl Fn(usize, &mut [Vec3], &mut [Vec3], &mut [C]) -> bool + Sync + Send,
) -> bool {
    if a.len() <= block {
        f(0, a, b, c)
    } else {
        a.par_chunks_mut(block)
            .zip(b.par_chunks_mut(block))
            .zip(c.par_chunks_mut(block))
            .enumerate()
            .map(|(k, ((a, b), c))| f(k * block, a, b, c))
            .reduce(|| true, |p, q| p & q)
    }
}

/// Particles per block when scanning for the first bad particle.
const SCAN_BLOCK: usize = 1 << 14;

/// The result of `f` for the lowest index `i < n` where it is `Some`: the same answer as a
/// sequential scan, found in parallel for large `n`.
pub(crate) fn find_first<T: Send>(
    n: usize,
    f: impl Fn(usize) -> Option<T> + Sync + Send,
) -> Option<T> {
    if n <= SCAN_BLOCK {
        (0..n).find_map(f)
    } else {
        (0..n)
            .into_par_iter()
            .with_min_len(SCAN_BLOCK)
            .find_map_first(f)
    }
}

/// Whether every position component is within `bound` (so finite) and every velocity is
/// finite: a branch-free scan the compiler vectorises, run on every step.
pub(crate) fn all_sane(x: &[Vec3], v: &[Vec3], bound: f64) -> bool {
    if x.len() <= SCAN_BLOCK {
        sane(x, v, bound)
    } else {
        x.par_chunks(SCAN_BLOCK)
            .zip(v.par_chunks(SCAN_BLOCK))
            .all(|(x, v)| sane(x, v, bound))
    }
}

/// [`all_sane`] for one block, inline: for integrators that check each block of particles
/// right after updating it, while it is still in cache.
#[inline]
pub(crate) fn sane(x: &[Vec3], v: &[Vec3], bound: f64) -> bool {
    // And-ing comparison results (not max, which skips NaN) keeps the loop branch-free and
    // vectorised; NaN fails every comparison, so it counts as out of bounds.
    let mut ok = true;
    for p in x {
        ok &= (p.x.abs() <= bound) & (p.y.abs() <= bound) & (p.z.abs() <= bound);
    }
    for p in v {
        ok &= p.x.is_finite() & p.y.is_finite() & p.z.is_finite();
    }
    ok
}

/// Elements per block of the vector helpers below.
const VECTOR_BLOCK: usize = 1 << 12;

/// `f(i, &mut out[i])` for every particle, in parallel blocks of [`VECTOR_BLOCK`].
pub(crate) fn for_each(out: &mut [Vec3], f: impl Fn(usize, &mut Vec3) + Sync + Send) {
    for_each_in(VECTOR_BLOCK, out, f);
}

/// `f(i, &mut out[i])` for every particle, in parallel blocks of `block` (inline when there
/// is only one).
pub(crate) fn for_each_in(
    block: usize,
    out: &mut [Vec3],
    f: impl Fn(usize, &mut Vec3) + Sync + Send,
) {
    if out.len() <= block {
        out.iter_mut().enumerate().for_each(|(i, o)| f(i, o));
    } else {
        out.par_chunks_mut(block)
            .enumerate()
            .for_each(|(b, chunk)| {
                for (k, o) in chunk.iter_mut().enumerate() {
                    f(b * block + k, o);
                }
            });
    }
}

/// `y += a x`.
pub(crate) fn axpy(y: &mut [Vec3], a: f64, x: &[Vec3]) {
    for_each(y, |i, y| *y += x[i] * a);
}

/// Most partial sums [`dot`] keeps (on the stack: a dot product allocates nothing).
const DOT_BLOCKS: usize = 1024;

/// `Σ a_i · b_i`, summed in fixed blocks whose partial sums are added in order: the same
/// bits on any number of threads. Blocks are [`VECTOR_BLOCK`] long up to
/// `DOT_BLOCKS × VECTOR_BLOCK` (4 M) elements and longer beyond, both fixed by the length.
pub(crate) fn dot(a: &[Vec3], b: &[Vec3]) -> f64 {
    let block = |(a, b): (&[Vec3], &[Vec3])| a.iter().zip(b).map(|(a, b)| a.dot(b)).sum::<f64>();
    if a.len() <= VECTOR_BLOCK {
        return block((a, b));
    }
    let len = VECTOR_BLOCK.max(a.len().div_ceil(DOT_BLOCKS));
    let blocks = a.len().div_ceil(len);
    let mut partial = [0.0f64; DOT_BLOCKS];
    partial[..blocks]
        .par_iter_mut()
        .zip(a.par_chunks(len).zip(b.par_chunks(len)))
        .for_each(|(p, chunk)| *p = block(chunk));
    partial[..blocks].iter().sum()
}
