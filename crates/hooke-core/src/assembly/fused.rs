//! One pass for a step that needs each particle's force once: partitions are scattered in
//! order and each stretch of particles is finished (its force summed, its state updated
//! in place) as soon as no later partition touches it, while its windows and state are
//! still in cache. The two-pass form (every partition, then every particle) streams the
//! windows out to memory and back, which at a million particles moves more bytes than the
//! particles themselves.
//!
//! Partition `q`'s springs have lower ends from `lo_q`, so once partitions `..=q` are
//! scattered, every particle below `lo_{q+1}` has its whole force, and no later partition
//! reads it: its state can be overwritten at once, which spares the step a second pair of
//! arrays to stream out (and the reads a write to memory not in cache costs first). Threads
//! take contiguous groups of partitions; a group cannot finish its first stretch until the
//! group before it has scattered its last partition, whose springs may reach into it, so
//! those first stretches are finished after all groups are scattered. When some window
//! reaches past the next stretch, every stretch waits for every scatter. Each particle's
//! sum adds the same windows in the same order as [`Assembly::gather_block`], whatever the
//! grouping: the bits do not depend on the thread count.

use super::{Assembly, Partition, REDUCE_BLOCK, scatter_partition, sum_windows};
use crate::particles::Vec3;
use std::marker::PhantomData;
use std::ops::Range;

/// What finishing a stretch of particles does: `finish(start, forces, x, v)` for particles
/// `start..start + forces.len()`, `forces` their spring forces, replacing their state
/// `(x, v)` by the new one; it returns whether that state is sane.
pub(crate) trait Finish:
    Fn(usize, &[Vec3], &mut [Vec3], &mut [Vec3]) -> bool + Sync
{
}
impl<F: Fn(usize, &[Vec3], &mut [Vec3], &mut [Vec3]) -> bool + Sync> Finish for F {}

/// Gives partition `k` of a group the buffer of partition `k - 2`, whose window no stretch
/// left to finish reads (the stretches it holds, `k - 2` and `k - 1`, are finished), when
/// each buffer fits the other's window. The group's first window stays, as the group's first
/// stretch is finished last. Scattering into a buffer that was written a moment ago, still
/// in cache, instead of a window last touched a step ago: at a million particles the
/// windows are 34 MB, which the step otherwise reads back and writes out again. Which
/// buffer holds a window changes no force.
fn reuse_window(own: &mut [Partition], k: usize) {
    debug_assert!(k >= 3);
    let (before, after) = own.split_at_mut(k);
    let (old, new) = (&mut before[k - 2], &mut after[0]);
    if old.capacity() >= new.len && new.capacity() >= old.len {
        std::mem::swap(&mut old.force, &mut new.force);
    }
}

/// The particles' state as the threads of a pass share it: positions, velocities and,
/// when saving, where each particle's position is copied before it is finished.
///
/// A pass reads a partition's window of particles while other threads update stretches of
/// particles, so neither can hold the arrays as a Rust slice whole. The pass keeps them
/// apart by construction: a stretch is updated only once no partition left to scatter reads
/// it, and no two threads update one stretch (see the module documentation).
#[derive(Clone, Copy)]
struct Shared<'a> {
    x: *mut Vec3,
    v: *mut Vec3,
    /// Null when not saving.
    saved: *mut Vec3,
    len: usize,
    arrays: PhantomData<&'a mut [Vec3]>,
}

// SAFETY: `Shared` hands out slices of `Vec3` (which is `Send` and `Sync`) only under the
// conditions its unsafe methods state, which make every access race-free.
#[allow(unsafe_code)]
unsafe impl Send for Shared<'_> {}
#[allow(unsafe_code)]
unsafe impl Sync for Shared<'_> {}

#[allow(unsafe_code)]
impl<'a> Shared<'a> {
    /// Shares `x` and `v` (of equal length) and `saved` (as long, or empty for no saving).
    fn new(x: &'a mut [Vec3], v: &'a mut [Vec3], saved: &'a mut [Vec3]) -> Self {
        assert!(v.len() == x.len() && (saved.is_empty() || saved.len() == x.len()));
        Self {
            len: x.len(),
            x: x.as_mut_ptr(),
            v: v.as_mut_ptr(),
            saved: if saved.is_empty() {
                std::ptr::null_mut()
            } else {
                saved.as_mut_ptr()
            },
            arrays: PhantomData,
        }
    }

    /// The positions and velocities of particles `range`, to read.
    ///
    /// # Safety
    /// No thread may write any of these particles while the slices live.
    unsafe fn read(self, range: Range<usize>) -> (&'a [Vec3], &'a [Vec3]) {
        assert!(range.start <= range.end && range.end <= self.len);
        // SAFETY: in bounds (checked), and not written meanwhile (the caller's promise).
        unsafe {
            (
                std::slice::from_raw_parts(self.x.add(range.start), range.len()),
                std::slice::from_raw_parts(self.v.add(range.start), range.len()),
            )
        }
    }

    /// The positions, velocities and saved positions (empty when not saving) of particles
    /// `range`, to write.
    ///
    /// # Safety
    /// No other access to these particles may happen while the slices live.
    unsafe fn write(self, range: Range<usize>) -> [&'a mut [Vec3]; 3] {
        assert!(range.start <= range.end && range.end <= self.len);
        let n = range.len();
        // SAFETY: in bounds (checked), and accessed through these slices alone (the
        // caller's promise); the three arrays are distinct allocations.
        unsafe {
            [
                std::slice::from_raw_parts_mut(self.x.add(range.start), n),
                std::slice::from_raw_parts_mut(self.v.add(range.start), n),
                if self.saved.is_null() {
                    &mut []
                } else {
                    std::slice::from_raw_parts_mut(self.saved.add(range.start), n)
                },
            ]
        }
    }
}

/// Finishes particles `range` in blocks of at most [`REDUCE_BLOCK`], each summing the
/// windows `windows(block)` lists, saving their positions first when `state` saves.
///
/// # Safety
/// Nothing else may access particles `range` meanwhile.
#[allow(unsafe_code)]
unsafe fn finish_range<'a, W: Iterator<Item = &'a Partition>>(
    range: Range<usize>,
    state: Shared<'_>,
    windows: impl Fn(Range<usize>) -> W,
    finish: &impl Finish,
) -> bool {
    // SAFETY: the caller's promise.
    let [x, v, saved] = unsafe { state.write(range.clone()) };
    let mut forces = [Vec3::zeros(); REDUCE_BLOCK];
    let mut sane = true;
    let mut start = range.start;
    while start < range.end {
        // Blocks end on multiples of REDUCE_BLOCK, where the listed windows change.
        let end = range.end.min((start / REDUCE_BLOCK + 1) * REDUCE_BLOCK);
        let (a, b) = (start - range.start, end - range.start);
        if !saved.is_empty() {
            saved[a..b].copy_from_slice(&x[a..b]);
        }
        let forces = &mut forces[..end - start];
        sum_windows(windows(start..end), start, forces);
        sane &= finish(start, forces, &mut x[a..b], &mut v[a..b]);
        start = end;
    }
    sane
}

/// What every group of a pass shares.
struct Pass<'a, F> {
    layout: Layout<'a>,
    /// Where each partition's stretch starts, then the particle count.
    at: &'a [usize],
    state: Shared<'a>,
    finish: &'a F,
}

impl<F: Finish> Pass<'_, F> {
    /// Splits partitions `q0..q0 + parts.len()` into `groups` contiguous groups, halving
    /// recursively (`rayon::join` allocates nothing), and runs `leaf(q0, parts)` on each;
    /// returns whether every leaf reported sanity.
    fn split<P: Send>(
        &self,
        (q0, parts): (usize, &mut [P]),
        groups: usize,
        leaf: &(impl Fn(usize, &mut [P]) -> bool + Sync),
    ) -> bool {
        if groups <= 1 || parts.len() <= 1 {
            return leaf(q0, parts);
        }
        let left = parts.len() * (groups / 2) / groups;
        let (lp, rp) = parts.split_at_mut(left);
        let (a, b) = rayon::join(
            || self.split((q0, lp), groups / 2, leaf),
            || self.split((q0 + left, rp), groups - groups / 2, leaf),
        );
        a & b
    }
}

/// The tables a partition's scatter reads.
pub(super) type Layout<'a> = (
    &'a super::SpringTable,
    &'a [super::Run],
    crate::assembly::kernel::Kernel,
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
            .all(|(q, p)| q + 2 >= at.len() - 1 || p.hi() <= at[q + 2])
    }

    /// Scatters every spring's force at the state `(x, v)` and finishes every particle once
    /// (see the module documentation), updating the state in place; when `saved` is not
    /// empty, each particle's position is copied there first. Returns whether every finish
    /// reported a sane state.
    #[allow(unsafe_code)]
    pub(crate) fn scatter_and_finish(
        &mut self,
        (x, v): (&mut [Vec3], &mut [Vec3]),
        saved: &mut [Vec3],
        finish: impl Finish,
    ) -> bool {
        let state = Shared::new(x, v, saved);
        let parts = self.partitions.len();
        if parts == 0 {
            let none = |_| std::iter::empty();
            // SAFETY: this thread alone holds the state.
            return unsafe { finish_range(0..self.particles, state, none, &finish) };
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
            state,
            finish: &finish,
        };
        // Each group scatters its partitions in order and finishes each stretch but its
        // first as soon as the stretch's partition is scattered.
        let scatter = |q0: usize, own: &mut [Partition]| {
            let (at, mut sane) = (pass.at, true);
            for k in 0..own.len() {
                if k >= 3 {
                    reuse_window(own, k);
                }
                let part = &mut own[k];
                // SAFETY: a window is updated by none while partitions are scattered: a
                // group updates only stretches below its next partition's window, and (with
                // the reach) the windows of the group before end in its first stretch, which
                // waits for every scatter. Without the reach a group is one partition and
                // updates nothing here.
                let (x, v) = unsafe { pass.state.read(part.lo..part.hi()) };
                scatter_partition(pass.layout, part, x, v);
                if k > 0 {
                    let q = q0 + k;
                    let near = &own[k - 1..=k];
                    // SAFETY: stretch `q` is this group's, below every window left to scatter
                    // (this group's next partition's starts at `at[q + 1]`, and later groups'
                    // beyond it), and no earlier group's window reaches past its own first stretch.
                    sane &= unsafe {
                        finish_range(at[q]..at[q + 1], pass.state, |_| near.iter(), pass.finish)
                    };
                }
            }
            sane
        };
        let mut sane = pass.split((0, &mut self.partitions[..]), groups, &scatter);
        // Then each group's first stretch, from every window that holds it.
        let this = &*self;
        let head = |q0: usize, _: &mut [()]| {
            let windows = |block: Range<usize>| {
                let parts = this.block_parts(block.start / REDUCE_BLOCK);
                parts.iter().map(|&q| &this.partitions[q as usize])
            };
            let stretch = this.stretch_at[q0]..this.stretch_at[q0 + 1];
            // SAFETY: every scatter is done, and each group updates its own first stretch.
            unsafe { finish_range(stretch, pass.state, windows, pass.finish) }
        };
        // The same split by partition count (a vector of `()` allocates nothing).
        let mut slots = vec![(); parts];
        sane &= pass.split((0, &mut slots[..]), groups, &head);
        sane
    }
}

#[cfg(test)]
mod tests {
    use crate::assembly::Assembly;
    use crate::assembly::kernel::tests::{bits, jumble, lattice, pool};
    use crate::particles::Vec3;

    /// The one-pass step updates the state in place to the bits the two-pass form gives
    /// (every window scattered at the old state, then every particle's sum), on one to four
    /// threads and step after step, with windows that reach one stretch (cloths of 3 and 33
    /// partitions, where groups of four or more hand window buffers on) and windows that
    /// reach everywhere (random springs); it saves the start positions when asked, and
    /// reports an insane stretch.
    #[test]
    fn the_one_pass_step_gives_the_two_pass_bits_in_place() {
        let cloth = |n: usize| lattice([1, n, n], 0, false);
        // Each case with whether its windows reach one stretch.
        let cases = [
            ("cloth 40", cloth(40), true),
            ("cloth 300", cloth(300), true),
            (
                "cloth 300 and random springs",
                lattice([1, 300, 300], 500, true),
                false,
            ),
            ("random springs", jumble(false, 100_000), false),
        ];
        let dt = 1e-3;
        let update = |forces: &[Vec3], x: &mut [Vec3], v: &mut [Vec3]| {
            for ((f, x), v) in forces.iter().zip(x).zip(v) {
                *v += f * dt;
                *x += *v * dt;
            }
        };
        for (name, (x0, v0, springs), reach) in cases {
            let n = x0.len();
            let (mut x, mut v) = (x0.clone(), v0.clone());
            let mut two_pass = Assembly::new(n, &springs);
            assert_eq!(two_pass.reach, reach, "{name}");
            let mut forces = vec![Vec3::zeros(); n];
            let mut expected = Vec::new();
            for _ in 0..3 {
                two_pass.scatter(&x, &v);
                two_pass.map_gathered(&mut forces, |_, f| f);
                update(&forces, &mut x, &mut v);
                expected.push((bits(&x), bits(&v)));
            }
            let insane = n / 2;
            for threads in 1..=4 {
                let pool = pool(threads);
                let mut asm = Assembly::new(n, &springs);
                let (mut x, mut v) = (x0.clone(), v0.clone());
                let mut saved = vec![Vec3::zeros(); n];
                for (step, (ex, ev)) in expected.iter().enumerate() {
                    let start = x.clone();
                    let save = step % 2 == 1;
                    let sane = pool.install(|| {
                        let saved = if save { &mut saved[..] } else { &mut [][..] };
                        asm.scatter_and_finish((&mut x, &mut v), saved, |at, f, x, v| {
                            update(f, x, v);
                            !(at..at + f.len()).contains(&insane)
                        })
                    });
                    let case = format!("{name}, {threads} threads, step {step}");
                    assert!(&bits(&x) == ex && &bits(&v) == ev, "{case}");
                    assert!(!sane, "{case}: particle {insane}'s stretch reported insane");
                    if save {
                        assert!(bits(&saved) == bits(&start), "{case}: saved start");
                    }
                }
            }
        }
    }
}
