//! A partition of the sorted springs and its window: the private buffer its forces are
//! scattered into before the per-particle gather (`mod.rs`).

use super::kernel::{Kernel, Run, RunArgs, ScatterArgs, Window};
use super::table::{RestLengths, SpringTable};
use crate::particles::Vec3;
use rayon::prelude::*;
use std::ops::Range;

/// A stretch of consecutive sorted springs and the window of particles they touch, with
/// the buffer their forces are scattered into.
#[derive(Clone, Debug)]
pub(super) struct Partition {
    /// The partition's springs, by assembly index.
    pub(super) springs: Range<usize>,
    /// Its pieces of runs in `Assembly::runs`, when it is laid out as runs; empty when its
    /// springs are stored in sorted order for the per-spring loop.
    pub(super) runs: Range<usize>,
    /// The first particle of the window.
    pub(super) lo: usize,
    /// The window's length: it covers particles `lo..lo + len`.
    pub(super) len: usize,
    /// The window's buffer, room for three values per particle. A partition laid out as
    /// runs keeps its forces by component, each component's in one of three equal thirds
    /// (its first `len` entries), so that the run loop adds a group of springs' forces with
    /// whole vectors and no transposition; one for the per-spring loop keeps each force
    /// whole in its first `3 len` values, as that loop updates one particle at a time. The
    /// buffer has room for the longest window where windows are of about one length, so
    /// that the one-pass step can hand a buffer still in cache from one partition to
    /// another (see `fused.rs`).
    pub(super) force: Vec<f64>,
}

impl Partition {
    /// Particles the buffer can hold.
    pub(super) fn capacity(&self) -> usize {
        self.force.len() / 3
    }

    /// Whether the window holds forces by component (the partition is laid out as runs).
    pub(super) fn by_component(&self) -> bool {
        !self.runs.is_empty()
    }

    /// The window by component, of a partition laid out as runs: the forces on particles
    /// `lo..lo + len`.
    pub(super) fn window(&self) -> [&[f64]; 3] {
        let third = self.capacity();
        [0, 1, 2].map(|c| &self.force[c * third..c * third + self.len])
    }

    /// The window with each force whole, of a partition for the per-spring loop.
    pub(super) fn whole(&self) -> &[Vec3] {
        bytemuck::cast_slice(&self.force[..3 * self.len])
    }

    /// [`Partition::whole`], to write.
    pub(super) fn whole_mut(&mut self) -> &mut [Vec3] {
        bytemuck::cast_slice_mut(&mut self.force[..3 * self.len])
    }

    /// Zeroes the window (as plain values: a fill with `Vec3::zeros()` stores one component
    /// at a time).
    pub(super) fn clear(&mut self) {
        if self.by_component() {
            for c in self.window_mut() {
                c.fill(0.0);
            }
        } else {
            self.force[..3 * self.len].fill(0.0);
        }
    }

    /// [`Partition::window`], to write.
    pub(super) fn window_mut(&mut self) -> Window<'_> {
        let (third, len) = (self.capacity(), self.len);
        let (x, rest) = self.force.split_at_mut(third);
        let (y, z) = rest.split_at_mut(third);
        [&mut x[..len], &mut y[..len], &mut z[..len]]
    }

    /// Where in the buffer component `c` of the force on particle `lo + k` is: in its
    /// third, or in the particle's triple.
    pub(super) fn at(&self, k: usize, c: usize) -> usize {
        if self.by_component() {
            c * self.capacity() + k
        } else {
            3 * k + c
        }
    }

    /// Adds the window's forces on particles `start..start + out.len()` (where they meet it)
    /// to `out`.
    pub(super) fn add_to(&self, start: usize, out: &mut [Vec3]) {
        let (lo, hi) = (self.lo.max(start), self.hi().min(start + out.len()));
        if lo < hi {
            let out = &mut out[lo - start..hi - start];
            if self.by_component() {
                let [x, y, z] = self.window().map(|c| &c[lo - self.lo..hi - self.lo]);
                for (k, o) in out.iter_mut().enumerate() {
                    *o += Vec3::new(x[k], y[k], z[k]);
                }
            } else {
                for (o, f) in out
                    .iter_mut()
                    .zip(&self.whole()[lo - self.lo..hi - self.lo])
                {
                    *o += f;
                }
            }
        }
    }

    /// One past the window's last particle.
    pub(super) fn hi(&self) -> usize {
        self.lo + self.len
    }

    /// The stretch of `(x, v)` the window covers: what [`scatter_partition`] reads.
    pub(super) fn read<'a>(&self, (x, v): (&'a [Vec3], &'a [Vec3])) -> (&'a [Vec3], &'a [Vec3]) {
        (&x[self.lo..self.hi()], &v[self.lo..self.hi()])
    }
}

/// Adds into `out` (particles `start..`, zeroed first) the windows of `parts` that hold
/// them, in the order given.
pub(super) fn sum_windows<'a>(
    parts: impl Iterator<Item = &'a Partition>,
    start: usize,
    out: &mut [Vec3],
) {
    // As plain values: filling with `Vec3::zeros()` stored one component at a time.
    bytemuck::cast_slice_mut::<Vec3, f64>(out).fill(0.0);
    for part in parts {
        part.add_to(start, out);
    }
}

/// Runs `f` on every partition: in parallel when there are several, inline for one (a small
/// system, where a rayon call would cost more than the springs).
pub(super) fn each_partition(
    partitions: &mut [Partition],
    f: impl Fn(&mut Partition) + Sync + Send,
) {
    if let [only] = partitions {
        f(only);
    } else {
        partitions.par_iter_mut().for_each(f);
    }
}

/// Computes the forces of `part`'s springs at `(x, v)`, the state of the window's particles
/// (see [`Partition::read`]), into its window.
pub(super) fn scatter_partition(
    (table, runs, kernel): (&SpringTable, &[Run], Kernel),
    part: &mut Partition,
    x: &[Vec3],
    v: &[Vec3],
) {
    let (lo, springs, pieces) = (part.lo, part.springs.clone(), part.runs.clone());
    part.clear();
    let uniform = table.param.is_empty();
    let params = &table.params[..];
    let runs = &runs[pieces];
    if !runs.is_empty() {
        macro_rules! runs {
            ($rest:expr) => {
                RunArgs {
                    springs: runs,
                    rest: $rest,
                    param: &table.param,
                    params,
                    lo,
                    force: part.window_mut(),
                    x,
                    v,
                }
            };
        }
        match (&table.rest, uniform) {
            (RestLengths::Indexed(index, rests), true) => {
                kernel.scatter_runs::<true, _>(runs!((&index[..], &rests[..])))
            }
            (RestLengths::Indexed(index, rests), false) => {
                kernel.scatter_runs::<false, _>(runs!((&index[..], &rests[..])))
            }
            (RestLengths::Each(rest), true) => kernel.scatter_runs::<true, _>(runs!(&rest[..])),
            (RestLengths::Each(rest), false) => kernel.scatter_runs::<false, _>(runs!(&rest[..])),
        }
        return;
    }
    let r = springs;
    let force = part.whole_mut();
    let ends = &table.ends[r.clone()];
    let param = if uniform {
        &[][..]
    } else {
        &table.param[r.clone()]
    };
    macro_rules! args {
        ($rest:expr) => {
            ScatterArgs {
                springs: ends,
                rest: $rest,
                param,
                params,
                lo,
                force,
                x,
                v,
            }
        };
    }
    match (&table.rest, uniform) {
        (RestLengths::Indexed(index, rests), true) => {
            kernel.scatter::<true, _>(args!((&index[r], &rests[..])))
        }
        (RestLengths::Indexed(index, rests), false) => {
            kernel.scatter::<false, _>(args!((&index[r], &rests[..])))
        }
        (RestLengths::Each(rest), true) => kernel.scatter::<true, _>(args!(&rest[r])),
        (RestLengths::Each(rest), false) => kernel.scatter::<false, _>(args!(&rest[r])),
    }
}
