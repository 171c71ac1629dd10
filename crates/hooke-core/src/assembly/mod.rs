//! Force assembly: spring forces accumulated in fixed partitions, then reduced per particle
//! in a fixed order.
//!
//! Springs are sorted by their lower particle index (ties keep the model's order) and cut
//! into partitions of consecutive springs, their size set by the spring count alone. Each
//! partition scatters its forces into a private buffer covering only the particles it
//! touches (its *window*); a second pass gives each particle the sum of its external force and of every
//! window holding it, in partition order. Partitions and reduction blocks are fixed by the
//! problem's size, never by the thread count, so the sums are the same bits on any number
//! of threads, with no atomics. Sorted springs of a mesh touch narrow windows, so the
//! buffers add little memory beyond one force per particle, and each partition reads
//! positions from a small, cache-resident stretch of the arrays.

mod fused;
pub(crate) mod kernel;
mod partition;
mod pieces;
mod small;
mod table;

use crate::assembly::kernel::{Kernel, Run};
use crate::forces::spring::Spring;
use crate::model::{Model, Near};
use crate::parallel;
use crate::particles::Vec3;
use rayon::prelude::*;
use std::collections::HashMap;

use partition::{Partition, each_partition, scatter_partition, sum_windows};
use pieces::{MIN_AVERAGE_PIECE, pieces};
use table::{RestLengths, SpringTable, intern};

/// Springs per partition: a thirty-second of the springs, within these bounds, then evened
/// out so that the partitions are of one size. Large systems get enough partitions for
/// two threads to finish together (the cloth-256 workload: 32 of 12k springs), each big
/// enough that windows overlap little (at most 32k springs); a 6k-spring jelly or a
/// 3.5k-spring cloth gets two, as each partition costs a rayon task and a window to clear
/// and gather, and at four RK4 stages per step those fixed costs rival the springs. A
/// function of the spring count alone, so the summation order never depends on the thread
/// count.
const PARTITION: (usize, usize) = (PARTITION_MIN, 1 << 15);
/// The fewest springs per partition; also the fewest per parallel task of per-spring work.
pub(crate) const PARTITION_MIN: usize = 1 << 12;

fn partition_size(springs: usize) -> usize {
    // From 2k to 8k springs (a small cloth, a jelly) two halves, not one partition: the
    // implicit integrator runs its products partition by partition 150 times a step.
    let min = PARTITION.0.min(springs.div_ceil(2)).max(PARTITION.0 / 4);
    let target = (springs / 32).clamp(min, PARTITION.1);
    springs.div_ceil(springs.div_ceil(target).max(1)).max(1)
}

/// Particles per reduction block: the gather adds external forces (a force field sample,
/// collider queries), costly enough to share a 512-particle jelly in two.
pub(crate) const REDUCE_BLOCK: usize = 256;

/// Particles per group asked at once which penalty colliders they may touch (see
/// [`Model::near`]): a layer of a small jelly, few enough that most groups are clear of
/// every wall but the one they rest on.
const NEAR_BLOCK: usize = 32;

/// Particles per block of the integrators' cheap per-particle updates: below this a
/// system is updated inline, as a rayon call would cost more than the work.
pub(crate) const BLOCK: usize = 1 << 12;
const _: () = assert!(BLOCK.is_multiple_of(REDUCE_BLOCK));

/// The solver's view of a model's springs, built once per run and reused every evaluation.
/// It copies the springs: rebuild it (a new [`crate::Workspace`]) after editing them.
///
/// Springs are sorted by their lower end, then upper end, and cut into partitions of
/// consecutive springs. A partition whose springs all belong to *runs* (springs whose ends
/// both advance by one particle from one to the next, see `kernel::run_loop`) is stored
/// as pieces of runs; any other keeps the sorted order for the per-spring loop. A mesh
/// numbered row by row (a grid, an extruded shape, the jelly) is all runs whatever its
/// shape; a graph without such regularity is laid out as before. Both loops add every
/// force in the sorted order's sequence, so the layout changes no bit of any result.
#[derive(Clone, Debug, Default)]
pub(crate) struct Assembly {
    table: SpringTable,
    runs: Vec<Run>,
    partitions: Vec<Partition>,
    /// For reduction block `b`, `block_parts[block_start[b]..block_start[b + 1]]` are the
    /// partitions whose window meets it, in order.
    block_start: Vec<u32>,
    block_parts: Vec<u32>,
    /// Where each partition's stretch of particles starts, then the particle count, and
    /// whether every window ends before the stretch after next (see `fused.rs`).
    stretch_at: Vec<usize>,
    reach: bool,
    particles: usize,
    kernel: Kernel,
    /// The threads' shares of a small system's particles (see `small.rs`).
    balance: small::Balance,
}

impl Assembly {
    /// Lays out `springs` over `particles` particles.
    ///
    /// # Panics
    /// If a spring names a particle that does not exist (a builder bug, not user input: scene
    /// loaders validate indices first).
    pub(crate) fn new(particles: usize, springs: &[Spring]) -> Self {
        Self::laid_out(particles, springs, Some(MIN_AVERAGE_PIECE))
    }

    /// [`Assembly::new`] with runs in partitions whose pieces average at least
    /// `min_average` springs, or with none (for tests that compare the two loops).
    pub(crate) fn laid_out(
        particles: usize,
        springs: &[Spring],
        min_average: Option<usize>,
    ) -> Self {
        for (k, s) in springs.iter().enumerate() {
            assert!(
                (s.i as usize) < particles && (s.j as usize) < particles,
                "spring {k} names particle {} or {} of {particles}",
                s.i,
                s.j
            );
        }
        let mut order: Vec<u32> = (0..springs.len() as u32).collect();
        order.sort_by_key(|&k| {
            let s = &springs[k as usize];
            (s.i.min(s.j), s.i.max(s.j))
        });
        let mut table = SpringTable::default();
        let mut rest = Vec::with_capacity(springs.len());
        let mut seen = HashMap::new();
        let mut push = |table: &mut SpringTable, k: u32| {
            let s = &springs[k as usize];
            // Lower index first: the force on the other end is the exact negation.
            table.ends.push([s.i.min(s.j), s.i.max(s.j)]);
            rest.push(s.rest);
            let key = [s.ks.to_bits(), s.kd.to_bits()];
            let index = intern(&mut seen, &mut table.params, key, [s.ks, s.kd]);
            table.param.push(index as u32);
        };
        let size = partition_size(springs.len());
        let mut runs = Vec::new();
        let mut partitions = Vec::new();
        for start in (0..springs.len()).step_by(size) {
            let range = start..(start + size).min(springs.len());
            let first_run = runs.len();
            match min_average.and_then(|min| pieces(springs, &order[range.clone()], min)) {
                Some(pieces) => {
                    for (lo, offset, members) in pieces {
                        let rest = |&k: &u32| springs[k as usize].rest.to_bits();
                        runs.push(Run {
                            lo,
                            offset,
                            len: members.len() as u32,
                            first: table.ends.len() as u32,
                            same_rest: members.iter().all(|k| rest(k) == rest(&members[0])),
                        });
                        for k in members {
                            push(&mut table, k);
                        }
                    }
                }
                None => {
                    for &k in &order[range.clone()] {
                        push(&mut table, k);
                    }
                }
            }
            let ends = table.ends[range.clone()].iter().flatten();
            let lo = ends.clone().copied().min().unwrap_or(0) as usize;
            let hi = ends.copied().max().unwrap_or(0) as usize;
            partitions.push(Partition {
                springs: range,
                runs: first_run..runs.len(),
                lo,
                len: hi + 1 - lo,
                force: Vec::new(),
            });
        }
        let longest = partitions.iter().map(|p| p.len).max().unwrap_or(0);
        let total: usize = partitions.iter().map(|p| p.len).sum();
        // Buffers of one length let every window use any buffer; when that would cost more
        // than half again the windows' own memory (windows of very unequal reach), each
        // keeps its own length and only buffers that fit trade places.
        let even = 2 * longest * partitions.len() <= 3 * total;
        for part in &mut partitions {
            part.force = vec![0.0; 3 * if even { longest } else { part.len }];
        }
        if table.params.len() == 1 {
            table.param = Vec::new();
        }
        table.rest = RestLengths::new(rest);
        let blocks = particles.div_ceil(REDUCE_BLOCK);
        let mut block_start = vec![0u32];
        let mut block_parts = Vec::new();
        for b in 0..blocks {
            let (lo, hi) = (b * REDUCE_BLOCK, ((b + 1) * REDUCE_BLOCK).min(particles));
            for (k, part) in partitions.iter().enumerate() {
                if part.lo < hi && part.hi() > lo {
                    block_parts.push(k as u32);
                }
            }
            block_start.push(block_parts.len() as u32);
        }
        let stretch_at = Self::stretches(&partitions, particles);
        let reach = Self::reaches_one_stretch(&partitions, &stretch_at);
        Self {
            table,
            runs,
            partitions,
            block_start,
            block_parts,
            stretch_at,
            reach,
            particles,
            kernel: Kernel::detect(),
            balance: small::Balance::default(),
        }
    }

    /// How many springs the layout keeps in runs.
    #[cfg(test)]
    pub(crate) fn springs_in_runs(&self) -> usize {
        self.runs.iter().map(|r| r.len as usize).sum()
    }

    /// Whether the rest lengths are read through an index (see `RestLengths`).
    #[cfg(test)]
    pub(crate) fn rest_indexed(&self) -> bool {
        matches!(self.table.rest, RestLengths::Indexed(..))
    }

    /// The compilation of the force loop in use: [`Kernel::detect`]'s unless set.
    pub(crate) fn kernel(&self) -> Kernel {
        self.kernel
    }

    /// Runs the force loop compiled for `kernel`, which must be one of
    /// [`Kernel::available`] (otherwise the detected one stays in use).
    pub(crate) fn set_kernel(&mut self, kernel: Kernel) {
        if kernel <= Kernel::detect() {
            self.kernel = kernel;
        }
    }

    /// Whether this layout was built for `particles` particles and `springs` springs.
    pub(crate) fn fits(&self, particles: usize, springs: usize) -> bool {
        self.particles == particles && self.table.ends.len() == springs
    }

    /// Computes every spring's force at `(x, v)` into the partition buffers.
    pub(crate) fn scatter(&mut self, x: &[Vec3], v: &[Vec3]) {
        let layout = (&self.table, &self.runs[..], self.kernel);
        each_partition(&mut self.partitions, |part| {
            let (x, v) = part.read((x, v));
            scatter_partition(layout, part, x, v)
        });
    }

    /// Scatters an antisymmetric per-spring quantity: `g(k, i, j)` is added at the spring's
    /// lower end `i` and subtracted at `j`; [`Assembly::map_gathered`] then reads the sums.
    /// `k` indexes the assembly's own (sorted) spring order, as [`crate::integrator::spring_blocks`]
    /// does. This is how the implicit integrator multiplies by its system matrix.
    pub(crate) fn scatter_pairs(&mut self, g: impl Fn(usize, usize, usize) -> Vec3 + Sync) {
        let table = &self.table;
        let scatter = |part: &mut Partition| {
            part.clear();
            for k in part.springs.clone() {
                let [i, j] = table.ends[k];
                let (i, j) = (i as usize, j as usize);
                let f = g(k, i, j);
                for (c, f) in f.iter().enumerate() {
                    let (a, b) = (part.at(i - part.lo, c), part.at(j - part.lo, c));
                    part.force[a] += f;
                    part.force[b] -= f;
                }
            }
        };
        each_partition(&mut self.partitions, scatter);
    }

    /// The end particles `[i, j]` (lower first) of the assembly's spring `k`.
    pub(crate) fn ends(&self, k: usize) -> [usize; 2] {
        let [i, j] = self.table.ends[k];
        [i as usize, j as usize]
    }

    /// The number of springs.
    pub(crate) fn springs(&self) -> usize {
        self.table.ends.len()
    }

    /// The rest length `l` of the assembly's spring `k`.
    pub(crate) fn rest(&self, k: usize) -> f64 {
        self.table.rest.get(k)
    }

    /// The stiffness and damping `[ks, kd]` of the assembly's spring `k`.
    pub(crate) fn params(&self, k: usize) -> [f64; 2] {
        self.table.params(k)
    }

    /// The partitions whose window meets reduction block `b`, in order.
    fn block_parts(&self, b: usize) -> &[u32] {
        &self.block_parts[self.block_start[b] as usize..self.block_start[b + 1] as usize]
    }

    /// The sums of the last scatter for particles `start..start + out.len()`, a block that
    /// starts on a multiple of [`REDUCE_BLOCK`] and spans at most one: each particle's total
    /// spring force after [`Assembly::scatter`], its row of the product after
    /// [`Assembly::scatter_pairs`]. Each particle's sum adds the windows holding it in
    /// partition order, so the bits do not depend on the thread count; each window's
    /// overlap with the block is added as one slice, so the per-particle loops that follow
    /// do no window lookups.
    pub(crate) fn gather_block(&self, start: usize, out: &mut [Vec3]) {
        debug_assert!(start.is_multiple_of(REDUCE_BLOCK) && out.len() <= REDUCE_BLOCK);
        let parts = self.block_parts(start / REDUCE_BLOCK);
        sum_windows(
            parts.iter().map(|&q| &self.partitions[q as usize]),
            start,
            out,
        );
    }

    /// Scatters at `(x, v)`, then sets `out[p] = map(p, F_p)` for every particle, `F_p` its
    /// total force, in parallel blocks. `extra` holds per-particle forces evaluated
    /// elsewhere (the air's), added to the springs'; empty for none.
    pub(crate) fn forces(
        &mut self,
        model: &Model,
        mass: &[f64],
        (x, v): (&[Vec3], &[Vec3]),
        extra: &[Vec3],
        out: &mut [Vec3],
        map: impl Fn(usize, Vec3) -> Vec3 + Sync + Send,
    ) {
        self.scatter(x, v);
        self.map_gathered(out, |p, springs| {
            map(
                p,
                total_force(model, mass, (x, v), extra, (p, Near::ALL), springs),
            )
        });
    }

    /// Sets `out[p] = map(p, S_p)` for every particle, `S_p` its sum from the last scatter
    /// (the windows holding `p` added in partition order), in parallel blocks.
    pub(crate) fn map_gathered(
        &self,
        out: &mut [Vec3],
        map: impl Fn(usize, Vec3) -> Vec3 + Sync + Send,
    ) {
        let block = |start: usize, out: &mut [Vec3]| {
            self.gather_block(start, out);
            for (k, o) in out.iter_mut().enumerate() {
                *o = map(start + k, *o);
            }
        };
        if out.len() <= REDUCE_BLOCK {
            block(0, out);
        } else {
            out.par_chunks_mut(REDUCE_BLOCK)
                .enumerate()
                .for_each(|(b, chunk)| block(b * REDUCE_BLOCK, chunk));
        }
    }

    /// `a = F(x, v) / m` for every particle, with `extra` as in [`Assembly::forces`];
    /// pinned particles get zero. The tests compare the small-system path with it.
    #[cfg(test)]
    pub(crate) fn accelerations(
        &mut self,
        model: &Model,
        (mass, inv_mass): (&[f64], &[f64]),
        (x, v): (&[Vec3], &[Vec3]),
        extra: &[Vec3],
        a: &mut [Vec3],
    ) {
        self.forces(model, mass, (x, v), extra, a, |p, f| {
            acceleration(inv_mass[p], f)
        });
    }

    /// Scatters at `(x, v)` and, for pieces of particles that cover them all once (each
    /// within one block of [`REDUCE_BLOCK`], in parallel), writes their accelerations to
    /// `a` as [`Assembly::accelerations`] does, then calls `then(start, a, o1, o2)` with the
    /// piece's stretch of `a` and of two more per-particle arrays. For integrator stages
    /// that write several arrays from each particle's acceleration: one pass over the
    /// particles, while the piece is in cache, instead of one per array. Systems of few
    /// partitions take one parallel call for all of it (see `small.rs`). Returns whether
    /// every call returned `true`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn accelerations_then(
        &mut self,
        model: &Model,
        (mass, inv_mass): (&[f64], &[f64]),
        (x, v): (&[Vec3], &[Vec3]),
        extra: &[Vec3],
        a: &mut [Vec3],
        (o1, o2): (&mut [Vec3], &mut [Vec3]),
        then: impl Fn(usize, &[Vec3], &mut [Vec3], &mut [Vec3]) -> bool + Sync + Send,
    ) -> bool {
        let finish = |start: usize, a: &mut [Vec3], o1: &mut [Vec3], o2: &mut [Vec3]| {
            accelerate(model, (mass, inv_mass), (x, v), extra, start, a);
            then(start, a, o1, o2)
        };
        if self.is_small() {
            return self.scatter_and_sum_small((x, v), (a, o1, o2), finish);
        }
        self.scatter(x, v);
        let this = &*self;
        parallel::all_blocks3(REDUCE_BLOCK, a, o1, o2, |start, a, o1, o2| {
            this.gather_block(start, a);
            finish(start, a, o1, o2)
        })
    }
}

/// Replaces the spring sums `a` of particles `start..start + a.len()` at `(x, v)` by their
/// accelerations, as [`Assembly::accelerations`] computes them, asking once per
/// [`NEAR_BLOCK`] particles which penalty colliders may touch them.
fn accelerate(
    model: &Model,
    (mass, inv_mass): (&[f64], &[f64]),
    (x, v): (&[Vec3], &[Vec3]),
    extra: &[Vec3],
    start: usize,
    a: &mut [Vec3],
) {
    for (c, a) in a.chunks_mut(NEAR_BLOCK).enumerate() {
        let start = start + c * NEAR_BLOCK;
        let near = model.near(&x[start..start + a.len()]);
        // Most of a jelly, away from the walls, feels only gravity besides its springs.
        let gravity_only = model.gravity_only_near(near);
        for (k, a) in a.iter_mut().enumerate() {
            let p = start + k;
            let f = if gravity_only {
                model.gravity * mass[p] + pairwise(extra, p, *a)
            } else {
                total_force(model, mass, (x, v), extra, (p, near), *a)
            };
            *a = acceleration(inv_mass[p], f);
        }
    }
}

/// Particle `p`'s spring forces `springs` plus the forces evaluated elsewhere, `extra`
/// (empty for none).
#[inline(always)]
fn pairwise(extra: &[Vec3], p: usize, springs: Vec3) -> Vec3 {
    // Without extra forces nothing is added, so their absence keeps every bit.
    if extra.is_empty() {
        springs
    } else {
        springs + extra[p]
    }
}

/// Particle `p`'s total force at `(x, v)`, `springs` its springs' sum and `extra` the
/// forces evaluated elsewhere (empty for none), asking the penalty colliders `near` lets
/// touch.
// Always inlined: as a call, its entry and exit were a tenth of a jelly particle's
// instructions (callgrind).
#[inline(always)]
fn total_force(
    model: &Model,
    mass: &[f64],
    (x, v): (&[Vec3], &[Vec3]),
    extra: &[Vec3],
    (p, near): (usize, Near),
    springs: Vec3,
) -> Vec3 {
    let pairwise = pairwise(extra, p, springs);
    model.total_force_near(p, (mass[p], &x[p], &v[p]), pairwise, near)
}

/// `f / m` for a particle of inverse mass `inv_mass`; zero for a pinned one.
#[inline]
fn acceleration(inv_mass: f64, f: Vec3) -> Vec3 {
    if inv_mass == 0.0 {
        Vec3::zeros()
    } else {
        f * inv_mass
    }
}
