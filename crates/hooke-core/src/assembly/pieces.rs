//! The layout of a partition's springs as pieces of runs (springs whose ends both advance
//! by one particle from one to the next), in the order the run loop takes them
//! (`kernel::run_loop`).

use super::kernel::{MAX_OFFSETS, RUN_CHUNK};
use crate::forces::spring::Spring;

/// The fewest springs per piece, on average, for a partition to be laid out as runs: below
/// it the per-spring loop, which batches springs across lower ends, is faster. A jelly
/// cube's rows of 8 particles make pieces of 9.8 springs on average, which ran 20 % slower
/// as runs; the built-in cloths' average 15 to 30.
pub(super) const MIN_AVERAGE_PIECE: usize = 12;

/// The pieces of runs of one partition's springs (`sorted`, model indices in sorted order),
/// each a lower end, an offset and its springs, in the order the run loop takes them: by
/// chunk of [`RUN_CHUNK`] lower ends, then by offset from the largest. `None` when the
/// partition is better or only correctly served by the per-spring loop: short pieces, a
/// chunk with pieces of more than [`MAX_OFFSETS`] offsets, or a spring given twice (whose
/// two forces the sorted order adds in the model's order, which pieces do not keep; the
/// run loop also relies on pieces of one offset covering distinct lower ends).
pub(super) fn pieces(
    springs: &[Spring],
    sorted: &[u32],
    min_average: usize,
) -> Option<Vec<(u32, u32, Vec<u32>)>> {
    let ends = |k: u32| {
        let s = &springs[k as usize];
        (s.i.min(s.j), s.i.max(s.j))
    };
    let mut by_offset = sorted.to_vec();
    by_offset.sort_by_key(|&k| {
        let (i, j) = ends(k);
        (j - i, i)
    });
    let mut pieces = Vec::new();
    let mut start = 0;
    while start < by_offset.len() {
        let (i0, j0) = ends(by_offset[start]);
        let mut end = start + 1;
        while end < by_offset.len() {
            let (i, j) = ends(by_offset[end]);
            if (i, j) == ends(by_offset[end - 1]) {
                return None;
            }
            let k = (end - start) as u32;
            if i != i0 + k || j != j0 + k {
                break;
            }
            end += 1;
        }
        // Cut where the lower ends cross a multiple of the chunk.
        let mut piece = start;
        while piece < end {
            let lo = i0 + (piece - start) as u32;
            let chunk_end = (lo as usize / RUN_CHUNK + 1) * RUN_CHUNK;
            let stop = end.min(piece + chunk_end - lo as usize);
            pieces.push((lo, j0 - i0, by_offset[piece..stop].to_vec()));
            piece = stop;
        }
        start = end;
    }
    if pieces.len() * min_average > sorted.len() {
        return None;
    }
    pieces.sort_by_key(|&(lo, offset, _)| (lo as usize / RUN_CHUNK, std::cmp::Reverse(offset)));
    let mut offsets = 0;
    for k in 0..pieces.len() {
        let chunk = pieces[k].0 as usize / RUN_CHUNK;
        if k == 0 || chunk != pieces[k - 1].0 as usize / RUN_CHUNK {
            offsets = 1;
        } else if pieces[k].1 != pieces[k - 1].1 {
            offsets += 1;
        }
        if offsets > MAX_OFFSETS {
            return None;
        }
    }
    Some(pieces)
}
