//! Searching by cells: primitives binned by their boxes into a uniform grid, each query
//! tested against the 27 cells around its own, in parallel over fixed chunks so that the
//! results' order is fixed by the positions alone (the detection's and the pair list's
//! searches, `detect/` and `candidates.rs`).

use crate::contact::grid::{Cell, Grid};
use crate::particles::Vec3;
use rayon::prelude::*;
use std::cell::RefCell;
use std::ops::Range;

/// A box as its low and high corners.
pub(in crate::integrator) type Aabb = (Vec3, Vec3);

/// A query's box by its index.
pub(in crate::integrator) type QueryBox<'a> = dyn Fn(usize) -> Aabb + Sync + 'a;

/// Queries (or primitives) per parallel chunk.
const CHUNK: usize = 512;

/// `f` over fixed chunks of `0..n`, in parallel when there are several, each chunk's result
/// in chunk order.
pub(in crate::integrator) fn per_chunk<R: Send>(
    n: usize,
    f: impl Fn(Range<usize>) -> R + Sync + Send,
) -> Vec<R> {
    if n <= CHUNK {
        return vec![f(0..n)];
    }
    (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| f(c * CHUNK..((c + 1) * CHUNK).min(n)))
        .collect()
}

/// `f` over fixed chunks of `0..n` as [`per_chunk`], each chunk filling its own buffer of
/// `buffers` (one per chunk, kept by the caller between calls, so that a call allocates
/// nothing once they have grown).
pub(in crate::integrator) fn each_chunk<R: Default + Send>(
    n: usize,
    buffers: &mut Vec<R>,
    f: impl Fn(Range<usize>, &mut R) + Sync + Send,
) {
    buffers.resize_with(n.div_ceil(CHUNK).max(1), R::default);
    if let [only] = &mut buffers[..] {
        return f(0..n, only);
    }
    buffers
        .par_iter_mut()
        .enumerate()
        .for_each(|(c, buffer)| f(c * CHUNK..((c + 1) * CHUNK).min(n), buffer));
}

/// `parts` end to end, in one allocation of exactly their length (a flattening collect
/// grows by doubling: up to twice the list, beside the parts, at the list's build).
pub(in crate::integrator) fn concatenate<T>(parts: Vec<Vec<T>>) -> Vec<T> {
    let mut out = Vec::with_capacity(parts.iter().map(Vec::len).sum());
    for part in parts {
        out.extend(part);
    }
    out
}

/// The box holding `points` (at least one).
pub(in crate::integrator) fn bounds_of(points: &[&Vec3]) -> (Vec3, Vec3) {
    let mut lo = *points[0];
    let mut hi = *points[0];
    for p in &points[1..] {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

/// Whether point `p` lies in box `lo..hi` grown by `r`.
pub(in crate::integrator) fn within(p: &Vec3, (lo, hi): &(Vec3, Vec3), r: f64) -> bool {
    (0..3).all(|k| p[k] >= lo[k] - r && p[k] <= hi[k] + r)
}

/// Whether boxes `a` and `b` come within `r` of each other.
pub(in crate::integrator) fn boxes_within(a: &(Vec3, Vec3), b: &(Vec3, Vec3), r: f64) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] + r && b.0[k] <= a.1[k] + r)
}

/// Bins `boxes` into `grid` with cells as large as the largest box plus `reach`, so that
/// everything within `reach` of a query lies in the 27 cells around it ([`by_cell`]).
pub(in crate::integrator) fn bin(grid: &mut Grid, boxes: &[(Vec3, Vec3)], reach: f64) {
    let extent = boxes
        .iter()
        .map(|(lo, hi)| (hi - lo).max())
        .fold(0.0, f64::max);
    grid.build(extent + reach, boxes.iter().map(|(lo, _)| *lo));
}

thread_local! {
    /// The flags a chunk of queries works with ([`Flags`]), kept per thread.
    static FLAGS: RefCell<Vec<bool>> = const { RefCell::new(Vec::new()) };
}

/// A flag per item, all clear between queries: a query sets those of its own list (the
/// items its pairs skip), reads them by index instead of searching the list for each
/// candidate (the search was a third of the pair list's build), and clears them.
pub(in crate::integrator) struct Flags(Vec<bool>);

impl Flags {
    /// `f` with the flags of `listed` set, and only those.
    pub(in crate::integrator) fn hold(&mut self, listed: &[u32], f: impl FnOnce(&[bool])) {
        for &k in listed {
            self.0[k as usize] = true;
        }
        f(&self.0);
        for &k in listed {
            self.0[k as usize] = false;
        }
    }
}

/// Calls `test(q, candidates, flags, out)` for every query `q` whose cell is `cells[q]`,
/// with the items of the 27 cells around that cell (every item whose low corner lies within
/// one cell of the query's), gathered once per occupied cell. Results come in the order of
/// (cell, query), in parts of consecutive cells, each part `finish`ed as soon as it is whole
/// (so that its slack goes before the next is grown): fixed by the positions alone, never
/// by threads.
///
/// `flags` has a flag per item, all clear ([`Flags`]), taken once per chunk.
///
/// `boxes` (each query's box, each item's box, the reach) prunes a cell's items to those
/// whose box comes within the reach of its queries' joint box (by a nanometre more, so
/// that rounding never drops one a query's own box test would keep): the same items reach
/// `test`, in the same order, fewer of those that none of the cell's queries can meet.
pub(in crate::integrator) fn by_cell<P: Default + Send>(
    grid: &Grid,
    cells: &[Cell],
    boxes: (&QueryBox<'_>, &[Aabb], f64),
    test: impl Fn(usize, &[u32], &mut Flags, &mut P) + Sync + Send,
    finish: impl Fn(&mut P) + Sync + Send,
) -> Vec<P> {
    let (query_box, item_boxes, reach) = boxes;
    let pad = reach + 1e-9;
    let mut order: Vec<u32> = (0..cells.len() as u32).collect();
    order.sort_unstable_by_key(|&q| (cells[q as usize], q));
    let mut starts: Vec<usize> = (0..order.len())
        .filter(|&k| k == 0 || cells[order[k] as usize] != cells[order[k - 1] as usize])
        .collect();
    starts.push(order.len());
    per_chunk(starts.len() - 1, |groups| {
        let mut out = P::default();
        let mut candidates = Vec::new();
        // The thread's flags, taken for the chunk: a panic drops them, never leaving any set.
        let mut flags = Flags(FLAGS.take());
        if flags.0.len() < item_boxes.len() {
            flags.0.resize(item_boxes.len(), false);
        }
        for g in groups {
            let members = &order[starts[g]..starts[g + 1]];
            let c = cells[members[0] as usize];
            candidates.clear();
            let mut joint = query_box(members[0] as usize);
            for &q in &members[1..] {
                let (lo, hi) = query_box(q as usize);
                joint = (joint.0.inf(&lo), joint.1.sup(&hi));
            }
            for i in -1..=1 {
                for j in -1..=1 {
                    for k in -1..=1 {
                        grid.visit([c[0] + i, c[1] + j, c[2] + k], |t| {
                            if boxes_within(&joint, &item_boxes[t as usize], pad) {
                                candidates.push(t);
                            }
                        });
                    }
                }
            }
            for &q in members {
                test(q as usize, &candidates, &mut flags, &mut out);
            }
        }
        FLAGS.set(flags.0);
        finish(&mut out);
        out
    })
}
