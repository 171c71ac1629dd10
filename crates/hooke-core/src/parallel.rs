//! Splitting per-particle work across threads without changing a bit of the result.

use crate::particles::Vec3;
use rayon::prelude::*;

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
