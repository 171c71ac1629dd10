//! Force assembly: spring forces accumulated in fixed partitions, then reduced per particle
//! in a fixed order.
//!
//! Springs are cut into partitions of [`PARTITION`] consecutive springs. Each partition
//! scatters its forces into a private buffer covering only the particles it touches (its
//! *window*); a second pass gives each particle the sum of its external force and of every
//! window holding it, in partition order. Partitions and reduction blocks are fixed by the
//! problem's size, never by the thread count, so the sums are the same bits on any number
//! of threads, with no atomics. Springs listed in mesh order touch narrow windows, so the
//! buffers add little memory beyond one force per particle.

use crate::model::Model;
use crate::particles::Vec3;
use crate::spring::{Spring, spring_force};
use rayon::prelude::*;
use std::collections::HashMap;
use std::ops::Range;

/// Springs per partition: enough work to be worth a task, small enough for two cores to
/// share the cloth-256 workload (392k springs, 24 partitions) evenly.
pub const PARTITION: usize = 1 << 14;

/// Particles per reduction block.
pub const BLOCK: usize = 1 << 12;

/// The springs of a model in the solver's layout: end pairs, rest lengths and an index into
/// a table of distinct `(ks, kd)` pairs, one array each, so the hot loop streams 20 bytes per
/// spring instead of the 40 of [`Spring`].
#[derive(Clone, Debug, Default)]
struct SpringTable {
    ends: Vec<[u32; 2]>,
    rest: Vec<f64>,
    param: Vec<u32>,
    params: Vec<[f64; 2]>,
}

#[derive(Clone, Debug)]
struct Partition {
    springs: Range<usize>,
    /// The first particle of the window.
    lo: usize,
    /// One force per particle of the window `lo..lo + force.len()`.
    force: Vec<Vec3>,
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
}

impl Assembly {
    /// Lays out `springs` over `particles` particles.
    ///
    /// # Panics
    /// If a spring names a particle that does not exist (a builder bug, not user input: scene
    /// loaders validate indices first).
    pub fn new(particles: usize, springs: &[Spring]) -> Self {
        let mut table = SpringTable::default();
        let mut seen: HashMap<[u64; 2], u32> = HashMap::new();
        for (k, s) in springs.iter().enumerate() {
            assert!(
                (s.i as usize) < particles && (s.j as usize) < particles,
                "spring {k} names particle {} or {} of {particles}",
                s.i,
                s.j
            );
            table.ends.push([s.i, s.j]);
            table.rest.push(s.rest);
            let key = [s.ks.to_bits(), s.kd.to_bits()];
            let next = table.params.len() as u32;
            let index = *seen.entry(key).or_insert(next);
            if index == next {
                table.params.push([s.ks, s.kd]);
            }
            table.param.push(index);
        }
        let partitions: Vec<Partition> = (0..springs.len())
            .step_by(PARTITION)
            .map(|start| {
                let range = start..(start + PARTITION).min(springs.len());
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
        let blocks = particles.div_ceil(BLOCK);
        let mut block_start = vec![0u32];
        let mut block_parts = Vec::new();
        for b in 0..blocks {
            let (lo, hi) = (b * BLOCK, ((b + 1) * BLOCK).min(particles));
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
        }
    }

    /// Whether this layout was built for `particles` particles and `springs` springs.
    pub fn fits(&self, particles: usize, springs: usize) -> bool {
        self.particles == particles && self.table.ends.len() == springs
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
        let table = &self.table;
        let scatter = |part: &mut Partition| {
            part.force.fill(Vec3::zeros());
            let lo = part.lo;
            for k in part.springs.clone() {
                let [i, j] = table.ends[k];
                let (i, j) = (i as usize, j as usize);
                let [ks, kd] = table.params[table.param[k] as usize];
                let f = spring_force(x[i] - x[j], v[i] - v[j], table.rest[k], ks, kd);
                part.force[i - lo] += f;
                part.force[j - lo] -= f;
            }
        };
        if self.partitions.len() == 1 {
            scatter(&mut self.partitions[0]);
        } else {
            self.partitions.par_iter_mut().for_each(scatter);
        }

        let partitions = &self.partitions;
        let (block_start, block_parts) = (&self.block_start, &self.block_parts);
        let gather = |(b, a): (usize, &mut [Vec3])| {
            let parts = &block_parts[block_start[b] as usize..block_start[b + 1] as usize];
            for (k, out) in a.iter_mut().enumerate() {
                let p = b * BLOCK + k;
                if inv_mass[p] == 0.0 {
                    *out = Vec3::zeros();
                    continue;
                }
                let mut f = model.external_force(mass[p], &x[p], &v[p]);
                for &q in parts {
                    let part = &partitions[q as usize];
                    if let Some(g) = p.checked_sub(part.lo).and_then(|w| part.force.get(w)) {
                        f += g;
                    }
                }
                *out = f / mass[p];
            }
        };
        if a.len() <= BLOCK {
            gather((0, a));
        } else {
            a.par_chunks_mut(BLOCK).enumerate().for_each(gather);
        }
    }
}
