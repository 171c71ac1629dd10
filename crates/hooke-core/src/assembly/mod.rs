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
mod small;

use crate::assembly::kernel::{Kernel, MAX_OFFSETS, RUN_CHUNK, Run, RunArgs, ScatterArgs, Window};
use crate::forces::spring::Spring;
use crate::model::{Model, Near};
use crate::parallel;
use crate::particles::Vec3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::ops::Range;

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

/// The springs of a model in the solver's layout: end pairs, rest lengths (see
/// [`RestLengths`]) and an index into a table of distinct `(ks, kd)` pairs, one array each,
/// so the hot loop streams 10 to 20 bytes per spring instead of the 40 of [`Spring`]
/// (`param` is left empty when all springs share one `(ks, kd)`).
#[derive(Clone, Debug, Default)]
struct SpringTable {
    ends: Vec<[u32; 2]>,
    rest: RestLengths,
    param: Vec<u32>,
    params: Vec<[f64; 2]>,
}

/// The springs' rest lengths: grid meshes have a handful of distinct ones (13 on the
/// cloth-512 workload), kept in a table read through a 2-byte index, which takes 6 bytes per
/// spring off the stream the force loop reads; other meshes keep one per spring, and so do
/// systems of at most [`INDEX_REST_ABOVE`] springs.
#[derive(Clone, Debug)]
enum RestLengths {
    Indexed(Vec<u16>, Vec<f64>),
    Each(Vec<f64>),
}

impl Default for RestLengths {
    fn default() -> Self {
        Self::Each(Vec::new())
    }
}

/// The index of `value` in `table`, which holds distinct values (told apart by `key`),
/// appending it when new.
fn intern<K: std::hash::Hash + Eq, V>(
    seen: &mut HashMap<K, usize>,
    table: &mut Vec<V>,
    key: K,
    value: V,
) -> usize {
    *seen.entry(key).or_insert_with(|| {
        table.push(value);
        table.len() - 1
    })
}

/// The fewest springs whose rest lengths are indexed. Below it they fit in a core's L2
/// cache whole, where the index saves no memory traffic and costs a dependent load per
/// spring (on `jello.w`, 6,220 springs in the per-spring loop, one RK4 step on one
/// thread took 201 µs indexed and 188 µs without).
const INDEX_REST_ABOVE: usize = 1 << 15;

impl RestLengths {
    /// Indexes `rest` when it has more than [`INDEX_REST_ABOVE`] values and at most 2¹⁶
    /// distinct ones (by bits).
    fn new(rest: Vec<f64>) -> Self {
        if rest.len() <= INDEX_REST_ABOVE {
            return Self::Each(rest);
        }
        let (mut seen, mut table) = (HashMap::new(), Vec::new());
        let mut index = Vec::with_capacity(rest.len());
        for &r in &rest {
            let Ok(k) = u16::try_from(intern(&mut seen, &mut table, r.to_bits(), r)) else {
                return Self::Each(rest);
            };
            index.push(k);
        }
        Self::Indexed(index, table)
    }

    fn get(&self, k: usize) -> f64 {
        match self {
            Self::Indexed(index, table) => table[index[k] as usize],
            Self::Each(rest) => rest[k],
        }
    }
}

impl SpringTable {
    #[inline]
    fn params(&self, k: usize) -> [f64; 2] {
        if self.param.is_empty() {
            self.params[0]
        } else {
            self.params[self.param[k] as usize]
        }
    }
}

#[derive(Clone, Debug)]
struct Partition {
    /// The partition's springs, by assembly index.
    springs: Range<usize>,
    /// Its pieces of runs in `Assembly::runs`, when it is laid out as runs; empty when its
    /// springs are stored in sorted order for the per-spring loop.
    runs: Range<usize>,
    /// The first particle of the window.
    lo: usize,
    /// The window's length: it covers particles `lo..lo + len`.
    len: usize,
    /// The window's buffer, room for three values per particle. A partition laid out as
    /// runs keeps its forces by component, each component's in one of three equal thirds
    /// (its first `len` entries), so that the run loop adds a group of springs' forces with
    /// whole vectors and no transposition; one for the per-spring loop keeps each force
    /// whole in its first `3 len` values, as that loop updates one particle at a time. The
    /// buffer has room for the longest window where windows are of about one length, so
    /// that the one-pass step can hand a buffer still in cache from one partition to
    /// another (see `fused.rs`).
    force: Vec<f64>,
}

impl Partition {
    /// Particles the buffer can hold.
    fn capacity(&self) -> usize {
        self.force.len() / 3
    }

    /// Whether the window holds forces by component (the partition is laid out as runs).
    fn by_component(&self) -> bool {
        !self.runs.is_empty()
    }

    /// The window by component, of a partition laid out as runs: the forces on particles
    /// `lo..lo + len`.
    fn window(&self) -> [&[f64]; 3] {
        let third = self.capacity();
        [0, 1, 2].map(|c| &self.force[c * third..c * third + self.len])
    }

    /// The window with each force whole, of a partition for the per-spring loop.
    fn whole(&self) -> &[Vec3] {
        bytemuck::cast_slice(&self.force[..3 * self.len])
    }

    /// [`Partition::whole`], to write.
    fn whole_mut(&mut self) -> &mut [Vec3] {
        bytemuck::cast_slice_mut(&mut self.force[..3 * self.len])
    }

    /// Zeroes the window (as plain values: a fill with `Vec3::zeros()` stores one component
    /// at a time).
    fn clear(&mut self) {
        if self.by_component() {
            for c in self.window_mut() {
                c.fill(0.0);
            }
        } else {
            self.force[..3 * self.len].fill(0.0);
        }
    }

    /// [`Partition::window`], to write.
    fn window_mut(&mut self) -> Window<'_> {
        let (third, len) = (self.capacity(), self.len);
        let (x, rest) = self.force.split_at_mut(third);
        let (y, z) = rest.split_at_mut(third);
        [&mut x[..len], &mut y[..len], &mut z[..len]]
    }

    /// Where in the buffer component `c` of the force on particle `lo + k` is: in its
    /// third, or in the particle's triple.
    fn at(&self, k: usize, c: usize) -> usize {
        if self.by_component() {
            c * self.capacity() + k
        } else {
            3 * k + c
        }
    }

    /// Adds the window's forces on particles `start..start + out.len()` (where they meet it)
    /// to `out`.
    fn add_to(&self, start: usize, out: &mut [Vec3]) {
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
    fn hi(&self) -> usize {
        self.lo + self.len
    }

    /// The stretch of `(x, v)` the window covers: what [`scatter_partition`] reads.
    fn read<'a>(&self, (x, v): (&'a [Vec3], &'a [Vec3])) -> (&'a [Vec3], &'a [Vec3]) {
        (&x[self.lo..self.hi()], &v[self.lo..self.hi()])
    }
}

/// Adds into `out` (particles `start..`, zeroed first) the windows of `parts` that hold
/// them, in the order given.
fn sum_windows<'a>(parts: impl Iterator<Item = &'a Partition>, start: usize, out: &mut [Vec3]) {
    // As plain values: filling with `Vec3::zeros()` stored one component at a time.
    bytemuck::cast_slice_mut::<Vec3, f64>(out).fill(0.0);
    for part in parts {
        part.add_to(start, out);
    }
}

/// The fewest springs per piece, on average, for a partition to be laid out as runs: below
/// it the per-spring loop, which batches springs across lower ends, is faster. A jelly
/// cube's rows of 8 particles make pieces of 9.8 springs on average, which ran 20 % slower
/// as runs; the built-in cloths' average 15 to 30.
const MIN_AVERAGE_PIECE: usize = 12;

/// Runs `f` on every partition: in parallel when there are several, inline for one (a small
/// system, where a rayon call would cost more than the springs).
fn each_partition(partitions: &mut [Partition], f: impl Fn(&mut Partition) + Sync + Send) {
    if let [only] = partitions {
        f(only);
    } else {
        partitions.par_iter_mut().for_each(f);
    }
}

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

/// The pieces of runs of one partition's springs (`sorted`, model indices in sorted order),
/// each a lower end, an offset and its springs, in the order the run loop takes them: by
/// chunk of [`RUN_CHUNK`] lower ends, then by offset from the largest. `None` when the
/// partition is better or only correctly served by the per-spring loop: short pieces, a
/// chunk with pieces of more than [`MAX_OFFSETS`] offsets, or a spring given twice (whose
/// two forces the sorted order adds in the model's order, which pieces do not keep; the
/// run loop also relies on pieces of one offset covering distinct lower ends).
fn pieces(
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

/// Computes the forces of `part`'s springs at `(x, v)`, the state of the window's particles
/// (see [`Partition::read`]), into its window.
fn scatter_partition(
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
