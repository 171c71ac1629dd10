//! Small systems in one parallel call per evaluation, split by measured time.
//!
//! A 512-particle jelly evaluates its forces in about 25 µs, so two joins per evaluation
//! (every partition scattered, then every particle summed) and a split of the particles
//! by count both cost a visible share of it: a join is a microsecond or two, and the half
//! of the jelly resting on a plane costs more per particle than the other. Here each thread
//! takes a group of consecutive partitions and a range of particles: it scatters its
//! partitions and publishes their windows, sums and finishes the pieces of its range that
//! its own windows alone hold, then the rest as the other windows are published. The
//! ranges are cut where the threads' last measured evaluations would have finished
//! together.
//!
//! A thread that needs a window nobody has begun scattering claims that partition and
//! scatters it itself, so it only ever waits for a partition that a running thread is
//! scattering, and the pass finishes on any number of threads (on one, the first group
//! scatters every partition it needs). Each particle adds the windows that hold it in
//! partition order, as [`Assembly::gather_block`] does: the cuts and the claims move work
//! between threads, never a bit of a result.

use super::{Assembly, Partition, REDUCE_BLOCK, scatter_partition, sum_windows};
use crate::particles::Vec3;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

/// The most partitions a system may have to be evaluated this way: systems up to 32k
/// springs (see `partition_size`). Larger ones have work enough per join.
pub(super) const MAX_PARTS: usize = 8;

/// Spins before a waiting thread starts yielding its core: a window is usually published
/// within a few microseconds, less than a sleep and wake-up would take.
const SPINS: u32 = 1 << 10;

/// Where each group's range of particles begins, adapted after every evaluation.
#[derive(Clone, Debug, Default)]
pub(super) struct Balance {
    /// The first particle of each group's range, then the particle count (fractional, so
    /// that small corrections accumulate).
    cut: Vec<f64>,
}

/// Raises its flag if dropped, which only unwinding does (the scatter it guards forgets it
/// when it returns).
struct Unwinding<'a>(&'a AtomicBool);

impl Drop for Unwinding<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// What one group measured: when it finished (ns after the pass began) and how long its
/// sums took.
#[derive(Default)]
struct Timing {
    done: AtomicU64,
    summing: AtomicU64,
}

/// The step after the sums: `f(start, sums, o1, o2)`, `sums` the spring sums of particles
/// `start..start + sums.len()`, to be replaced by whatever the caller keeps, `o1`, `o2` their
/// stretch of two more arrays. Returns whether their new state is sane.
pub(crate) trait Finish3:
    Fn(usize, &mut [Vec3], &mut [Vec3], &mut [Vec3]) -> bool + Sync
{
}
impl<F: Fn(usize, &mut [Vec3], &mut [Vec3], &mut [Vec3]) -> bool + Sync> Finish3 for F {}

/// What every group of one evaluation shares.
struct Pass<'a, F> {
    layout: super::fused::Layout<'a>,
    block_start: &'a [u32],
    block_parts: &'a [u32],
    /// Each partition's window, `lo..lo + len` (empty past the last partition).
    extent: [Range<usize>; MAX_PARTS],
    /// Each partition until a thread claims it to scatter it.
    unclaimed: &'a [Mutex<Option<&'a mut Partition>>],
    /// Each partition's window once scattered.
    published: &'a [OnceLock<&'a Partition>],
    /// Set when a scatter panicked, so that threads waiting for its window stop.
    failed: AtomicBool,
    /// The first partition of each group, then the partition count.
    first: [usize; MAX_PARTS + 1],
    /// The first particle of each group's range, then the particle count.
    cut: [usize; MAX_PARTS + 1],
    state: (&'a [Vec3], &'a [Vec3]),
    timing: &'a [Timing],
    begun: Instant,
    finish: &'a F,
}

impl<'a, F: Finish3> Pass<'a, F> {
    /// Partition `q`'s scattered window: published already, or scattered here if no thread
    /// has claimed it, or awaited from the thread scattering it.
    fn window(&self, q: usize) -> &'a Partition {
        let mut spins = 0;
        loop {
            if let Some(part) = self.published[q].get() {
                return part;
            }
            if let Ok(mut slot) = self.unclaimed[q].try_lock()
                && let Some(part) = slot.take()
            {
                drop(slot);
                let (x, v) = self.state;
                let unwinding = Unwinding(&self.failed);
                let (x, v) = part.read((x, v));
                scatter_partition(self.layout, part, x, v);
                std::mem::forget(unwinding);
                let part: &'a Partition = part;
                let _ = self.published[q].set(part);
                return part;
            }
            // Its window will never come: let rayon carry the scatter's panic out.
            assert!(
                !self.failed.load(Ordering::Relaxed),
                "a partition's scatter panicked on another thread"
            );
            // A window is usually published within a few microseconds, sooner than a
            // sleep and wake-up would take.
            if spins < SPINS {
                spins += 1;
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
    }

    /// Groups `groups`, whose ranges are the arrays given: halves recursively with
    /// `rayon::join`.
    fn split(
        &self,
        groups: Range<usize>,
        (a, o1, o2): (&mut [Vec3], &mut [Vec3], &mut [Vec3]),
    ) -> bool {
        if groups.len() == 1 {
            return self.group(groups.start, (a, o1, o2));
        }
        let mid = groups.start + groups.len() / 2;
        let at = self.cut[mid] - self.cut[groups.start];
        let (la, ra) = a.split_at_mut(at);
        let (l1, r1) = o1.split_at_mut(at);
        let (l2, r2) = o2.split_at_mut(at);
        let (left, right) = rayon::join(
            || self.split(groups.start..mid, (la, l1, l2)),
            || self.split(mid..groups.end, (ra, r1, r2)),
        );
        left & right
    }

    /// The partitions whose windows hold `piece` (which lies in one reduction block), in
    /// order.
    fn holding(&self, piece: &Range<usize>) -> impl Iterator<Item = usize> + '_ {
        let b = piece.start / REDUCE_BLOCK;
        let listed =
            &self.block_parts[self.block_start[b] as usize..self.block_start[b + 1] as usize];
        let (start, end) = (piece.start, piece.end);
        listed
            .iter()
            .map(|&q| q as usize)
            .filter(move |&q| self.extent[q].start < end && self.extent[q].end > start)
    }

    /// `range` in pieces held by one set of windows each, cut at reduction blocks and at
    /// the windows' ends.
    fn pieces(&self, range: Range<usize>) -> impl Iterator<Item = Range<usize>> + '_ {
        let mut start = range.start;
        std::iter::from_fn(move || {
            if start >= range.end {
                return None;
            }
            let mut end = range.end.min((start / REDUCE_BLOCK + 1) * REDUCE_BLOCK);
            for e in &self.extent {
                for edge in [e.start, e.end] {
                    if edge > start && edge < end {
                        end = edge;
                    }
                }
            }
            let piece = start..end;
            start = end;
            Some(piece)
        })
    }

    /// Group `g`: scatters its partitions, then sums and finishes its range: first the
    /// pieces its own windows hold alone, then, as the other windows are published, the
    /// rest.
    fn group(&self, g: usize, (a, o1, o2): (&mut [Vec3], &mut [Vec3], &mut [Vec3])) -> bool {
        let own = self.first[g]..self.first[g + 1];
        for q in own.clone() {
            self.window(q);
        }
        let summing = Instant::now();
        let range = self.cut[g]..self.cut[g + 1];
        let mut sane = true;
        for foreign in [false, true] {
            for piece in self.pieces(range.clone()) {
                if self.holding(&piece).any(|q| !own.contains(&q)) != foreign {
                    continue;
                }
                let windows = self.holding(&piece).map(|q| self.window(q));
                let (i, j) = (piece.start - range.start, piece.end - range.start);
                sum_windows(windows, piece.start, &mut a[i..j]);
                sane &= (self.finish)(piece.start, &mut a[i..j], &mut o1[i..j], &mut o2[i..j]);
            }
        }
        let timing = &self.timing[g];
        timing
            .summing
            .store(summing.elapsed().as_nanos() as u64, Ordering::Relaxed);
        timing
            .done
            .store(self.begun.elapsed().as_nanos() as u64, Ordering::Relaxed);
        sane
    }
}

impl Balance {
    /// The cuts for `groups` groups of `particles`: the adapted ones, or an even split
    /// when the grouping is new.
    fn cuts(&mut self, groups: usize, particles: usize) -> [usize; MAX_PARTS + 1] {
        if self.cut.len() != groups + 1 || self.cut[groups] != particles as f64 {
            self.cut = (0..=groups)
                .map(|g| (particles * g / groups) as f64)
                .collect();
        }
        let mut cut = [particles; MAX_PARTS + 1];
        cut[0] = 0;
        for (g, cut) in cut.iter_mut().enumerate().take(groups).skip(1) {
            self.cut[g] = self.cut[g].clamp(self.cut[g - 1], particles as f64);
            *cut = self.cut[g].round() as usize;
        }
        cut
    }

    /// Moves each cut toward where the groups on either side would have finished together,
    /// by half the measured difference (the other half is left to the next evaluations, as
    /// single measurements are noisy).
    fn adapt(&mut self, timing: &[Timing], cut: &[usize]) {
        for g in 1..timing.len() {
            let late = |t: &Timing| t.done.load(Ordering::Relaxed) as f64;
            let lateness = late(&timing[g - 1]) - late(&timing[g]);
            let summing = |t: &Timing| t.summing.load(Ordering::Relaxed) as f64;
            let particles = (cut[g + 1] - cut[g - 1]) as f64;
            let per_particle = (summing(&timing[g - 1]) + summing(&timing[g])) / particles;
            if per_particle > 0.0 {
                // Moving one particle across a cut changes the difference by two.
                self.cut[g] -= 0.5 * lateness / (2.0 * per_particle);
            }
        }
    }
}

impl Assembly {
    /// Whether [`Assembly::scatter_and_sum_small`] serves this system.
    pub(super) fn is_small(&self) -> bool {
        self.partitions.len() <= MAX_PARTS
    }

    /// Scatters at `(x, v)` and calls `finish(start, sums, o1, o2)` on pieces of particles
    /// that cover them all once, each within one reduction block, `sums` their spring sums
    /// (in `a`), in one parallel call (see the module documentation). Returns whether every
    /// call returned `true`.
    pub(super) fn scatter_and_sum_small(
        &mut self,
        (x, v): (&[Vec3], &[Vec3]),
        (a, o1, o2): (&mut [Vec3], &mut [Vec3], &mut [Vec3]),
        finish: impl Finish3,
    ) -> bool {
        let parts = self.partitions.len();
        let groups = parts.min(rayon::current_num_threads()).max(1);
        let mut first = [parts; MAX_PARTS + 1];
        for (g, f) in first.iter_mut().enumerate().take(groups) {
            *f = parts * g / groups;
        }
        let cut = self.balance.cuts(groups, self.particles);
        let mut extent: [Range<usize>; MAX_PARTS] = Default::default();
        for (e, part) in extent.iter_mut().zip(&self.partitions) {
            *e = part.lo..part.hi();
        }
        let unclaimed: [Mutex<Option<&mut Partition>>; MAX_PARTS] = Default::default();
        for (slot, part) in unclaimed.iter().zip(self.partitions.iter_mut()) {
            *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some(part);
        }
        let published: [OnceLock<&Partition>; MAX_PARTS] = Default::default();
        let timing: [Timing; MAX_PARTS] = Default::default();
        let pass = Pass {
            layout: (&self.table, &self.runs[..], self.kernel),
            block_start: &self.block_start,
            block_parts: &self.block_parts,
            extent,
            unclaimed: &unclaimed,
            published: &published,
            failed: AtomicBool::new(false),
            first,
            cut,
            state: (x, v),
            timing: &timing[..groups],
            begun: Instant::now(),
            finish: &finish,
        };
        let sane = pass.split(0..groups, (a, o1, o2));
        self.balance.adapt(&timing[..groups], &cut);
        sane
    }
}

#[cfg(test)]
mod tests {
    use crate::assembly::Assembly;
    use crate::assembly::kernel::tests::{bits, jumble, pool};
    use crate::collider::response::Response;
    use crate::collider::{Collider, Contact};
    use crate::forces::spring::{Spring, SpringKind};
    use crate::model::{ColliderSlot, Model};
    use crate::particles::Vec3;

    /// A penalty floor at height `y` that answers [`Collider::may_touch`].
    #[derive(Debug)]
    struct Floor(f64);

    impl Collider for Floor {
        fn name(&self) -> String {
            "floor".to_string()
        }

        fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
            if p.y < self.0 {
                sink(Contact {
                    depth: self.0 - p.y,
                    normal: Vec3::y(),
                    point: Vec3::new(p.x, self.0, p.z),
                });
            }
        }

        fn may_touch(&self, lo: &Vec3, _: &Vec3, margin: f64) -> bool {
            let clear = lo.y - self.0 >= margin;
            !clear
        }
    }

    /// The one-call pass (up to [`super::MAX_PARTS`] partitions, here 1, 2 and 5) gives the
    /// accelerations of the two-pass [`Assembly::accelerations`] to the bit on one to four
    /// threads, evaluation after evaluation, and finishes every particle once; so does the
    /// two-pass form of `accelerations_then` past it (10 partitions). The floor at 0.3
    /// meets most groups of particles, so groups are asked per particle; the one at -5
    /// meets none, so every group takes the gravity-only sums.
    #[test]
    fn the_one_call_pass_gives_the_two_pass_bits_on_any_thread_count() {
        for (count, floor) in [
            (0, 0.3),
            (5_000, 0.3),
            (20_000, 0.3),
            (20_000, -5.0),
            (40_000, 0.3),
        ] {
            let (x, v, springs) = jumble(false, count);
            let n = x.len();
            let model = Model {
                springs: springs.clone(),
                gravity: Vec3::new(0.0, -9.81, 0.0),
                colliders: vec![ColliderSlot {
                    shape: Box::new(Floor(floor)),
                    response: Response::Penalty { kc: 1e3, dc: 2.0 },
                }],
                ..Model::default()
            };
            let mass: Vec<f64> = (0..n).map(|i| 1.0 + (i % 3) as f64).collect();
            let inv: Vec<f64> = (0..n)
                .map(|i| if i % 100 == 0 { 0.0 } else { 1.0 / mass[i] })
                .collect();
            let masses = (&mass[..], &inv[..]);
            let mut expected = vec![Vec3::zeros(); n];
            Assembly::new(n, &springs).accelerations(&model, masses, (&x, &v), &[], &mut expected);
            for threads in 1..=4 {
                let pool = pool(threads);
                let mut asm = Assembly::new(n, &springs);
                assert_eq!(asm.is_small(), count < 40_000, "{count} springs");
                for round in 0..3 {
                    let mut a = vec![Vec3::zeros(); n];
                    let (mut copy, mut seen) = (a.clone(), a.clone());
                    let sane = pool.install(|| {
                        let out = (&mut copy[..], &mut seen[..]);
                        asm.accelerations_then(
                            &model,
                            masses,
                            (&x, &v),
                            &[],
                            &mut a,
                            out,
                            |start, a, copy, seen| {
                                copy.copy_from_slice(a);
                                for (k, seen) in seen.iter_mut().enumerate() {
                                    *seen += Vec3::repeat((start + k) as f64);
                                }
                                !(start..start + a.len()).contains(&1234)
                            },
                        )
                    });
                    let case =
                        format!("{count} springs, floor {floor}, {threads} threads, round {round}");
                    assert_eq!(bits(&a), bits(&expected), "{case}");
                    assert_eq!(bits(&copy), bits(&expected), "{case}");
                    assert!(
                        seen.iter()
                            .enumerate()
                            .all(|(i, s)| *s == Vec3::repeat(i as f64)),
                        "{case}"
                    );
                    assert!(!sane, "{case}: particle 1234's block reported insane");
                }
            }
        }
    }

    /// A scatter that panics (here: positions for all particles but the last, a caller's
    /// bug that only the second partition's springs reach) fails the pass on every thread
    /// count, instead of leaving the thread that needs its window waiting for it.
    #[test]
    fn a_panicking_scatter_fails_the_pass_instead_of_hanging_it() {
        let n = 3000;
        let spring = |i: usize, j: usize| Spring {
            i: i as u32,
            j: j as u32,
            rest: 0.1,
            ks: 100.0,
            kd: 0.5,
            kind: SpringKind::Other,
        };
        let springs: Vec<Spring> = (0..n - 1)
            .map(|i| spring(i, i + 1))
            .chain((0..n - 200).map(|i| spring(i, i + 200)))
            .collect();
        let model = Model {
            springs: springs.clone(),
            ..Model::default()
        };
        let (x, mass) = (vec![Vec3::zeros(); n], vec![1.0; n]);
        for threads in 1..=3 {
            let pool = pool(threads);
            let mut asm = Assembly::new(n, &springs);
            let (mut a, mut o1, mut o2) = (x.clone(), x.clone(), x.clone());
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                pool.install(|| {
                    let short = (&x[..n - 1], &x[..n - 1]);
                    let out = (&mut o1[..], &mut o2[..]);
                    asm.accelerations_then(
                        &model,
                        (&mass, &mass),
                        short,
                        &[],
                        &mut a,
                        out,
                        |_, _, _, _| true,
                    )
                })
            }));
            assert!(result.is_err(), "{threads} threads");
        }
    }
}
