//! One pass for a step that needs each particle's force once: partitions are scattered in
//! order and each stretch of particles is finished (its force summed, its new state
//! written) as soon as no later partition touches it, while its windows and state are
//! still in cache. The two-pass form (every partition, then every particle) streams the
//! windows out to memory and back, which at a million particles moves more bytes than the
//! particles themselves.
//!
//! Partition `q`'s springs have lower ends from `lo_q`, so once partitions `..=q` are
//! scattered, every particle below `lo_{q+1}` has its whole force, and no later partition
//! reads it. The pass reads the old state and writes the new one to other arrays, so the
//! stretches a thread finishes never alias what another thread reads. Threads take
//! contiguous groups of partitions; a group cannot finish its first stretch until the
//! group before it has scattered its last partition, whose springs may reach into it, so
//! those first stretches are finished after all groups are scattered. Each particle's sum
//! adds the same windows in the same order as [`Assembly::gather_block`], whatever the
//! grouping: the bits do not depend on the thread count.

use super::{Assembly, Partition, REDUCE_BLOCK, scatter_partition};
use crate::particles::Vec3;
use std::ops::Range;

/// What finishing a stretch of particles does: `finish(start, forces, x_new, v_new)` for
/// particles `start..start + forces.len()`, `forces` their spring forces, writing their new
/// state; it returns whether that state is sane.
pub(crate) trait Finish:
    Fn(usize, &[Vec3], &mut [Vec3], &mut [Vec3]) -> bool + Sync
{
}
impl<F: Fn(usize, &[Vec3], &mut [Vec3], &mut [Vec3]) -> bool + Sync> Finish for F {}

/// Adds into `out` (particles `start..`, zeroed first) the windows of `parts` that hold
/// them, in the order given.
pub(super) fn sum_windows<'a>(
    parts: impl Iterator<Item = &'a Partition>,
    start: usize,
    out: &mut [Vec3],
) {
    out.fill(Vec3::zeros());
    let end = start + out.len();
    for part in parts {
        let (lo, hi) = (part.lo.max(start), (part.lo + part.force.len()).min(end));
        if lo < hi {
            let window = &part.force[lo - part.lo..hi - part.lo];
            for (o, f) in out[lo - start..hi - start].iter_mut().zip(window) {
                *o += f;
            }
        }
    }
}

/// Finishes particles `range` (whose new state is `xn`, `vn`) in blocks of at most
/// [`REDUCE_BLOCK`], each summing the windows `windows(block)` lists.
fn finish_range<'a, W: Iterator<Item = &'a Partition>>(
    range: Range<usize>,
    xn: &mut [Vec3],
    vn: &mut [Vec3],
    windows: impl Fn(Range<usize>) -> W,
    finish: &impl Finish,
) -> bool {
    let mut forces = [Vec3::zeros(); REDUCE_BLOCK];
    let mut sane = true;
    let mut start = range.start;
    while start < range.end {
        // Blocks end on multiples of REDUCE_BLOCK, where the listed windows change.
        let end = range.end.min((start / REDUCE_BLOCK + 1) * REDUCE_BLOCK);
        let (a, b) = (start - range.start, end - range.start);
        let forces = &mut forces[..end - start];
        sum_windows(windows(start..end), start, forces);
        sane &= finish(start, forces, &mut xn[a..b], &mut vn[a..b]);
        start = end;
    }
    sane
}

/// What every group of a pass shares.
struct Pass<'a, F> {
    layout: Layout<'a>,
    /// Where each partition's stretch starts, then the particle count.
    at: &'a [usize],
    state: (&'a [Vec3], &'a [Vec3]),
    finish: &'a F,
}

impl<F: Finish> Pass<'_, F> {
    /// Splits partitions `q0..q0 + parts.len()` and their particles' new state into `groups`
    /// contiguous groups, halving recursively (`rayon::join` allocates nothing), and runs
    /// `leaf(q0, parts, xn, vn)` on each; returns whether every leaf reported sanity.
    fn split<P: Send>(
        &self,
        (q0, parts): (usize, &mut [P]),
        (xn, vn): (&mut [Vec3], &mut [Vec3]),
        groups: usize,
        leaf: &(impl Fn(usize, &mut [P], &mut [Vec3], &mut [Vec3]) -> bool + Sync),
    ) -> bool {
        if groups <= 1 || parts.len() <= 1 {
            return leaf(q0, parts, xn, vn);
        }
        let left = parts.len() * (groups / 2) / groups;
        let mid = self.at[q0 + left] - self.at[q0];
        let (lp, rp) = parts.split_at_mut(left);
        let ((lx, rx), (lv, rv)) = (xn.split_at_mut(mid), vn.split_at_mut(mid));
        let (a, b) = rayon::join(
            || self.split((q0, lp), (lx, lv), groups / 2, leaf),
            || self.split((q0 + left, rp), (rx, rv), groups - groups / 2, leaf),
        );
        a & b
    }
}

/// The tables a partition's scatter reads.
pub(super) type Layout<'a> = (
    &'a super::SpringTable,
    &'a [super::Run],
    crate::kernel::Kernel,
);

impl Assembly {
    /// Where each partition's stretch starts: particle 0, then each later partition's first
    /// lower end, then the particle count.
    pub(super) fn stretches(partitions: &[Partition], particles: usize) -> Vec<usize> {
        let mut at: Vec<usize> = std::iter::once(0)
            .chain(partitions.iter().skip(1).map(|p| p.lo))
            .collect();
        at.push(particles);
        at
    }

    /// Whether every partition's window ends before the stretch after next begins: then a
    /// stretch is held only by its own partition's window and the one before, and a group
    /// of partitions reaches no further than the next group's first stretch.
    pub(super) fn reaches_one_stretch(partitions: &[Partition], at: &[usize]) -> bool {
        partitions
            .iter()
            .enumerate()
            .all(|(q, p)| q + 2 >= at.len() - 1 || p.lo + p.force.len() <= at[q + 2])
    }

    /// Scatters every spring's force at the old state `(x, v)` and finishes every particle
    /// once (see the module documentation), writing the new state to `(xn, vn)`. Returns
    /// whether every finish reported a sane state.
    pub(crate) fn scatter_and_finish(
        &mut self,
        (x, v): (&[Vec3], &[Vec3]),
        (xn, vn): (&mut [Vec3], &mut [Vec3]),
        finish: impl Finish,
    ) -> bool {
        let parts = self.partitions.len();
        if parts == 0 {
            let none = |_| std::iter::empty();
            return finish_range(0..self.particles, xn, vn, none, &finish);
        }
        // Without the reach, each partition is its own group: scatter all, then finish all.
        let groups = if self.reach {
            parts.min(rayon::current_num_threads())
        } else {
            parts
        };
        let pass = Pass {
            layout: (&self.table, &self.runs[..], self.kernel),
            at: &self.stretch_at,
            state: (x, v),
            finish: &finish,
        };
        // Each group scatters its partitions in order and finishes each stretch but its
        // first as soon as the stretch's partition is scattered.
        let scatter = |q0: usize, own: &mut [Partition], xn: &mut [Vec3], vn: &mut [Vec3]| {
            let (at, mut sane) = (pass.at, true);
            for k in 0..own.len() {
                scatter_partition(pass.layout, &mut own[k], pass.state.0, pass.state.1);
                if k > 0 {
                    let q = q0 + k;
                    let (a, b) = (at[q] - at[q0], at[q + 1] - at[q0]);
                    let near = &own[k - 1..=k];
                    sane &= finish_range(
                        at[q]..at[q + 1],
                        &mut xn[a..b],
                        &mut vn[a..b],
                        |_| near.iter(),
                        pass.finish,
                    );
                }
            }
            sane
        };
        let mut sane = pass.split(
            (0, &mut self.partitions[..]),
            (&mut *xn, &mut *vn),
            groups,
            &scatter,
        );
        // Then each group's first stretch, from every window that holds it.
        let this = &*self;
        let head = |q0: usize, _: &mut [()], xn: &mut [Vec3], vn: &mut [Vec3]| {
            let end = this.stretch_at[q0 + 1] - this.stretch_at[q0];
            finish_range(
                this.stretch_at[q0]..this.stretch_at[q0 + 1],
                &mut xn[..end],
                &mut vn[..end],
                |block: Range<usize>| {
                    let parts = this.block_parts(block.start / REDUCE_BLOCK);
                    parts.iter().map(|&q| &this.partitions[q as usize])
                },
                pass.finish,
            )
        };
        // The same split by partition count (a vector of `()` allocates nothing).
        let mut slots = vec![(); parts];
        sane &= pass.split((0, &mut slots[..]), (xn, vn), groups, &head);
        sane
    }
}
