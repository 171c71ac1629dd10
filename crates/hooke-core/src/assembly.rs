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

use crate::kernel::Kernel;
use crate::model::Model;
use crate::particles::Vec3;
use crate::spring::{Spring, SpringBatch};
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
const PARTITION_MIN: usize = 1 << 12;

fn partition_size(springs: usize) -> usize {
    // From 2k to 8k springs (a small cloth, a jelly) two halves, not one partition: the
    // implicit integrator runs its products partition by partition 150 times a step.
    let min = PARTITION.0.min(springs.div_ceil(2)).max(PARTITION.0 / 4);
    let target = (springs / 32).clamp(min, PARTITION.1);
    springs.div_ceil(springs.div_ceil(target).max(1)).max(1)
}

/// Particles per reduction block: the gather adds external forces (a force field sample,
/// collider queries), costly enough to share a 512-particle jelly in two.
pub const REDUCE_BLOCK: usize = 256;

/// Particles per block of the integrators' cheap per-particle updates: below this a
/// system is updated inline, as a rayon call would cost more than the work.
pub const BLOCK: usize = 1 << 12;
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
/// spring off the stream the force loop reads; other meshes keep one per spring.
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

impl RestLengths {
    /// Indexes `rest` when it has at most 2¹⁶ distinct values (by bits).
    fn new(rest: Vec<f64>) -> Self {
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

/// Where the force loop reads a batch's rest lengths.
pub(crate) trait Rest: Copy + Send + Sync {
    /// The rest length of the `l`-th spring of the slice.
    fn rest(self, l: usize) -> f64;
    /// Springs `range` of the slice.
    fn slice(self, range: Range<usize>) -> Self;
}

impl Rest for &[f64] {
    #[inline(always)]
    fn rest(self, l: usize) -> f64 {
        self[l]
    }
    #[inline(always)]
    fn slice(self, range: Range<usize>) -> Self {
        &self[range]
    }
}

impl Rest for (&[u16], &[f64]) {
    #[inline(always)]
    fn rest(self, l: usize) -> f64 {
        self.1[self.0[l] as usize]
    }
    #[inline(always)]
    fn slice(self, range: Range<usize>) -> Self {
        (&self.0[range], self.1)
    }
}

/// A symmetric 3×3 matrix: `[xx, yy, zz, xy, xz, yz]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sym3(pub [f64; 6]);

impl Sym3 {
    /// `u uᵀ`.
    pub fn outer(u: &Vec3) -> Self {
        Self([
            u.x * u.x,
            u.y * u.y,
            u.z * u.z,
            u.x * u.y,
            u.x * u.z,
            u.y * u.z,
        ])
    }

    /// `s · self`.
    pub fn scale(self, s: f64) -> Self {
        Self(self.0.map(|v| v * s))
    }

    /// `self + s I`.
    pub fn plus_identity(mut self, s: f64) -> Self {
        for k in 0..3 {
            self.0[k] += s;
        }
        self
    }

    /// `self + other`.
    pub fn plus(self, other: &Sym3) -> Self {
        Self(std::array::from_fn(|k| self.0[k] + other.0[k]))
    }

    /// `self · v`.
    #[inline]
    pub fn mul(&self, v: &Vec3) -> Vec3 {
        let [xx, yy, zz, xy, xz, yz] = self.0;
        Vec3::new(
            xx * v.x + xy * v.y + xz * v.z,
            xy * v.x + yy * v.y + yz * v.z,
            xz * v.x + yz * v.y + zz * v.z,
        )
    }

    /// The inverse, or `None` when the matrix is singular.
    pub fn inverse(&self) -> Option<Self> {
        let [a, d, f, b, c, e] = self.0;
        // Cofactors of [[a b c] [b d e] [c e f]].
        let (ca, cb, cc) = (d * f - e * e, c * e - b * f, b * e - c * d);
        let det = a * ca + b * cb + c * cc;
        if det.abs() <= f64::MIN_POSITIVE {
            return None;
        }
        let inv = 1.0 / det;
        Some(Self([
            ca * inv,
            (a * f - c * c) * inv,
            (a * d - b * b) * inv,
            cb * inv,
            cc * inv,
            (b * c - a * e) * inv,
        ]))
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

/// Springs per batch of the force loop.
pub(crate) const LANES: usize = 64;

/// Adds the forces of the springs `ends`/`rest` into `force`, the window of particles from
/// `lo`. With `UNIFORM`, every spring has stiffness and damping `params[0]`; otherwise
/// spring `k` has `params[param[k]]`.
///
/// Springs go in batches of [`LANES`], in three passes: load each spring's end
/// differences into the batch, compute the batch's forces in one vectorised loop
/// ([`SpringBatch::run`]), then add them to the ends. The middle pass is where the
/// arithmetic is, and only there can the compiler run several springs per instruction; the
/// outer passes move data between the particles' layout and the batch's.
#[inline(always)]
pub(crate) fn scatter_springs<const UNIFORM: bool, R: Rest, B: SpringBatch<LANES>>(
    ScatterArgs {
        ends,
        rest,
        param,
        params,
        lo,
        force,
        x,
        v,
    }: ScatterArgs<R>,
) {
    // Equal lengths let one bounds check on `x` cover `v` too.
    let v = &v[..x.len()];
    let mut batch = B::default();
    if UNIFORM {
        let [ks, kd] = params[0];
        batch.set_all_params(ks, kd);
    }
    // Springs sharing a lower end are consecutive: sum their pull on it in a register and
    // store once, instead of a store-to-load chain through memory per spring.
    let mut current = lo;
    let mut pull = Vec3::zeros();
    let (mut lower, mut xi, mut vi) = (usize::MAX, Vec3::zeros(), Vec3::zeros());
    for (b, ends) in ends.chunks(LANES).enumerate() {
        // `n <= LANES` is what lets the compiler drop the batch's bounds checks.
        let n = ends.len().min(LANES);
        let rest = rest.slice(b * LANES..b * LANES + n);
        for (l, &[i, j]) in ends[..n].iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            // Consecutive springs mostly share their lower end: load it once per run.
            if i != lower {
                lower = i;
                (xi, vi) = (x[i], v[i]);
            }
            batch.set(l, &(xi - x[j]), &(vi - v[j]), rest.rest(l));
            if !UNIFORM {
                let [ks, kd] = params[param[b * LANES + l] as usize];
                batch.set_params(l, ks, kd);
            }
        }
        batch.run(n);
        for (l, &[i, j]) in ends[..n].iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            let f = batch.force(l);
            if i != current {
                force[current - lo] += pull;
                pull = Vec3::zeros();
                current = i;
            }
            pull += f;
            force[j - lo] -= f;
        }
    }
    force[current - lo] += pull;
}

/// The arguments of [`scatter_springs`] for one partition.
pub(crate) struct ScatterArgs<'a, R> {
    /// The springs' ends, lower end first.
    pub ends: &'a [[u32; 2]],
    /// Their rest lengths.
    pub rest: R,
    /// Each spring's index into `params` (empty when every spring has `params[0]`).
    pub param: &'a [u32],
    /// The distinct `(ks, kd)` pairs.
    pub params: &'a [[f64; 2]],
    /// The window's first particle.
    pub lo: usize,
    /// The window's forces, particle `lo + k` at `k`.
    pub force: &'a mut [Vec3],
    /// Positions.
    pub x: &'a [Vec3],
    /// Velocities.
    pub v: &'a [Vec3],
}

#[derive(Clone, Debug)]
struct Partition {
    springs: Range<usize>,
    /// The first particle of the window.
    lo: usize,
    /// One force per particle of the window `lo..lo + force.len()`.
    force: Vec<Vec3>,
}

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
#[derive(Clone, Debug, Default)]
pub struct Assembly {
    table: SpringTable,
    partitions: Vec<Partition>,
    /// For reduction block `b`, `block_parts[block_start[b]..block_start[b + 1]]` are the
    /// partitions whose window meets it, in order.
    block_start: Vec<u32>,
    block_parts: Vec<u32>,
    particles: usize,
    kernel: Kernel,
}

impl Assembly {
    /// Lays out `springs` over `particles` particles.
    ///
    /// # Panics
    /// If a spring names a particle that does not exist (a builder bug, not user input: scene
    /// loaders validate indices first).
    pub fn new(particles: usize, springs: &[Spring]) -> Self {
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
        for &k in &order {
            let s = &springs[k as usize];
            // Lower index first: the force on the other end is the exact negation.
            table.ends.push([s.i.min(s.j), s.i.max(s.j)]);
            rest.push(s.rest);
            let key = [s.ks.to_bits(), s.kd.to_bits()];
            let index = intern(&mut seen, &mut table.params, key, [s.ks, s.kd]);
            table.param.push(index as u32);
        }
        if table.params.len() == 1 {
            table.param = Vec::new();
        }
        table.rest = RestLengths::new(rest);
        let partitions: Vec<Partition> = (0..springs.len())
            .step_by(partition_size(springs.len()))
            .map(|start| {
                let range = start..(start + partition_size(springs.len())).min(springs.len());
                let ends = table.ends[range.clone()].iter().flatten();
                let lo = ends.clone().copied().min().unwrap_or(0) as usize;
                let hi = ends.copied().max().unwrap_or(0) as usize;
                Partition {
                    springs: range,
                    lo,
                    force: vec![Vec3::zeros(); hi + 1 - lo],
                }
            })
            .collect();
        let blocks = particles.div_ceil(REDUCE_BLOCK);
        let mut block_start = vec![0u32];
        let mut block_parts = Vec::new();
        for b in 0..blocks {
            let (lo, hi) = (b * REDUCE_BLOCK, ((b + 1) * REDUCE_BLOCK).min(particles));
            for (k, part) in partitions.iter().enumerate() {
                if part.lo < hi && part.lo + part.force.len() > lo {
                    block_parts.push(k as u32);
                }
            }
            block_start.push(block_parts.len() as u32);
        }
        Self {
            table,
            partitions,
            block_start,
            block_parts,
            particles,
            kernel: Kernel::detect(),
        }
    }

    /// The compilation of the force loop in use: [`Kernel::detect`]'s unless set.
    pub fn kernel(&self) -> Kernel {
        self.kernel
    }

    /// Runs the force loop compiled for `kernel`, which must be one of
    /// [`Kernel::available`] (otherwise the detected one stays in use).
    pub fn set_kernel(&mut self, kernel: Kernel) {
        if kernel <= Kernel::detect() {
            self.kernel = kernel;
        }
    }

    /// Whether this layout was built for `particles` particles and `springs` springs.
    pub fn fits(&self, particles: usize, springs: usize) -> bool {
        self.particles == particles && self.table.ends.len() == springs
    }

    /// Computes every spring's force at `(x, v)` into the partition buffers.
    pub fn scatter(&mut self, x: &[Vec3], v: &[Vec3]) {
        let (table, kernel) = (&self.table, self.kernel);
        let scatter = |part: &mut Partition| {
            part.force.fill(Vec3::zeros());
            let r = part.springs.clone();
            let ends = &table.ends[r.clone()];
            let uniform = table.param.is_empty();
            let param = if uniform {
                &[][..]
            } else {
                &table.param[r.clone()]
            };
            let (lo, force) = (part.lo, &mut part.force[..]);
            let params = &table.params[..];
            macro_rules! args {
                ($rest:expr) => {
                    ScatterArgs {
                        ends,
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
        };
        each_partition(&mut self.partitions, scatter);
    }

    /// Scatters an antisymmetric per-spring quantity: `g(k, i, j)` is added at the spring's
    /// lower end `i` and subtracted at `j`; [`Assembly::map_gathered`] then reads the sums.
    /// `k` indexes the assembly's own (sorted) spring order, as [`Assembly::spring_blocks`]
    /// does. This is how the implicit integrator multiplies by its system matrix.
    pub fn scatter_pairs(&mut self, g: impl Fn(usize, usize, usize) -> Vec3 + Sync) {
        let table = &self.table;
        let scatter = |part: &mut Partition| {
            part.force.fill(Vec3::zeros());
            let lo = part.lo;
            for k in part.springs.clone() {
                let [i, j] = table.ends[k];
                let (i, j) = (i as usize, j as usize);
                let f = g(k, i, j);
                part.force[i - lo] += f;
                part.force[j - lo] -= f;
            }
        };
        each_partition(&mut self.partitions, scatter);
    }

    /// The end particles `[i, j]` (lower first) of the assembly's spring `k`.
    pub fn ends(&self, k: usize) -> [usize; 2] {
        let [i, j] = self.table.ends[k];
        [i as usize, j as usize]
    }

    /// Each spring's force derivatives at `x`, as positive semi-definite blocks (in the
    /// contract's names, `L = |x_i - x_j|` the length now, `l` the rest length,
    /// `u = (x_i - x_j)/L`): the elastic `Kₛ = ks (u uᵀ + max(0, 1 - l/L)(I - u uᵀ))`, so that
    /// `∂f_i/∂x_i = -Kₛ`, and the damping `Dₛ = kd u uᵀ`, `∂f_i/∂v_i = -Dₛ`. The transverse
    /// term is clamped at zero for compressed springs (Choi & Ko 2002), which keeps the
    /// implicit system positive definite.
    pub fn spring_blocks(&self, x: &[Vec3], out: &mut Vec<[Sym3; 2]>) {
        let table = &self.table;
        out.resize(table.ends.len(), [Sym3::default(); 2]);
        let block = |k: usize| {
            let [i, j] = table.ends[k];
            let d = x[i as usize] - x[j as usize];
            let len = d.norm();
            if len < crate::spring::DEGENERATE_LENGTH {
                return [Sym3::default(); 2];
            }
            let u = d * (1.0 / len);
            let [ks, kd] = table.params(k);
            let uu = Sym3::outer(&u);
            let transverse = (1.0 - table.rest.get(k) / len).max(0.0);
            let elastic = uu
                .scale(ks * (1.0 - transverse))
                .plus_identity(ks * transverse);
            [elastic, uu.scale(kd)]
        };
        if out.len() <= PARTITION.0 {
            out.iter_mut().enumerate().for_each(|(k, o)| *o = block(k));
        } else {
            out.par_iter_mut()
                .with_min_len(PARTITION.0)
                .enumerate()
                .for_each(|(k, o)| *o = block(k));
        }
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
        out.fill(Vec3::zeros());
        let end = start + out.len();
        for &q in self.block_parts(start / REDUCE_BLOCK) {
            let part = &self.partitions[q as usize];
            let (lo, hi) = (part.lo.max(start), (part.lo + part.force.len()).min(end));
            if lo < hi {
                let window = &part.force[lo - part.lo..hi - part.lo];
                for (o, f) in out[lo - start..hi - start].iter_mut().zip(window) {
                    *o += f;
                }
            }
        }
    }

    /// The total force on particle `p` at `(x, v)` given `springs`, its spring sum: external
    /// forces, attachments and springs.
    #[inline]
    pub fn force(model: &Model, mass: f64, x: &Vec3, v: &Vec3, p: usize, springs: Vec3) -> Vec3 {
        let f = model.external_force(p, mass, x, v) + springs;
        if model.attachments.is_empty() {
            f
        } else {
            f + model.attachment_force(p, x, v)
        }
    }

    /// Scatters at `(x, v)`, then sets `out[p] = map(p, F_p)` for every particle, `F_p` its
    /// total force, in parallel blocks.
    pub fn forces(
        &mut self,
        model: &Model,
        mass: &[f64],
        (x, v): (&[Vec3], &[Vec3]),
        out: &mut [Vec3],
        map: impl Fn(usize, Vec3) -> Vec3 + Sync + Send,
    ) {
        self.scatter(x, v);
        self.map_gathered(out, |p, springs| {
            map(p, Self::force(model, mass[p], &x[p], &v[p], p, springs))
        });
    }

    /// Sets `out[p] = map(p, S_p)` for every particle, `S_p` its sum from the last scatter
    /// (the windows holding `p` added in partition order), in parallel blocks.
    pub fn map_gathered(&self, out: &mut [Vec3], map: impl Fn(usize, Vec3) -> Vec3 + Sync + Send) {
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

    /// `a = F(x, v) / m` for every particle; pinned particles get zero.
    pub fn accelerations(
        &mut self,
        model: &Model,
        (mass, inv_mass): (&[f64], &[f64]),
        x: &[Vec3],
        v: &[Vec3],
        a: &mut [Vec3],
    ) {
        self.forces(model, mass, (x, v), a, |p, f| {
            if inv_mass[p] == 0.0 {
                Vec3::zeros()
            } else {
                f * inv_mass[p]
            }
        });
    }
}
