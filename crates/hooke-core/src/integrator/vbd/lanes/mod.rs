//! The inertia, drag and springs of block descent's updates, eight particles of a colour at
//! a time (docs/physics.md §4.1, "the sweep").
//!
//! One particle at a time, a spring's square root and five divisions are scalar
//! instructions, an eighth of a register's width under AVX-512. Here each colour's particles
//! are taken in blocks of eight, and each block's springs are laid out row by row (row `k`
//! holds every lane's `k`-th spring: the other particle, rest length and coefficients), so
//! that one row is one pass of vector instructions over the block: one AVX-512 register or
//! two AVX2 ones, the other particles' positions gathered. The kernel is the explicit
//! force loop's [`Kernel`], chosen at run time; the portable one sums one particle at a time
//! (`Local::springs`). Every lane does that sum's correctly rounded operations in its order
//! (no fused multiply-adds), and a lane with no spring in a row keeps its sums as they were,
//! so every kernel gives the same bits, as a test checks.

use super::graph::{Graph, Neighbour};
use super::local::{Block, Local};
use crate::assembly::kernel::Kernel;
use crate::particles::Vec3;
use std::array::from_fn;

#[cfg(target_arch = "x86_64")]
mod wide;

/// Particles summed at once: an AVX-512 register of `f64`s, two of AVX2, four of SSE2.
pub(in crate::integrator) const LANES: usize = 8;

/// One value per lane.
type Row = [f64; LANES];

/// One colour's springs laid out for the lanes: its particles in blocks of [`LANES`] (the
/// last one may be short), each block's springs row by row.
#[derive(Clone, Debug, Default)]
struct Stream {
    /// Per block: its first row and its number of rows (its particles' most springs).
    blocks: Vec<(u32, u32)>,
    /// Per block: each lane's particle's first coordinate's index (three times the
    /// particle; the block's first particle's past the colour's end), and its spring count
    /// (0 past the colour's end).
    own: Vec<[i32; LANES]>,
    counts: Vec<Row>,
    /// Per row: each lane's other particle's first coordinate's index (the lane's own
    /// particle's where it has no spring in the row, so that every load is in bounds),
    /// rest length and coefficients.
    other: Vec<[i32; LANES]>,
    rest: Vec<Row>,
    ks: Vec<Row>,
    kd: Vec<Row>,
}

/// A particle's first coordinate's index in its positions seen as `f64`s.
fn coordinate(i: u32) -> i32 {
    i32::try_from(3 * u64::from(i)).expect("fewer than 715 million particles")
}

impl Stream {
    /// Lays out the springs of `colour`'s particles.
    fn fill(&mut self, graph: &Graph, colour: &[u32]) {
        self.blocks.clear();
        self.own.clear();
        self.counts.clear();
        self.other.clear();
        self.rest.clear();
        self.ks.clear();
        self.kd.clear();
        // The rows in one allocation each, of exactly their number: grown by doubling, four
        // of the five row arrays held 40 % slack (3.7 MB of the 128² cloth).
        let rows: usize = colour
            .chunks(LANES)
            .map(|ids| {
                ids.iter()
                    .map(|&i| graph.of(i as usize).len())
                    .max()
                    .unwrap_or(0)
            })
            .sum();
        self.other.reserve_exact(rows);
        self.rest.reserve_exact(rows);
        self.ks.reserve_exact(rows);
        self.kd.reserve_exact(rows);
        for ids in colour.chunks(LANES) {
            let lists: [&[Neighbour]; LANES] =
                from_fn(|l| ids.get(l).map_or(&[][..], |&i| graph.of(i as usize)));
            let rows = lists.iter().map(|s| s.len()).max().unwrap_or(0);
            self.blocks.push((self.other.len() as u32, rows as u32));
            let own: [i32; LANES] = from_fn(|l| coordinate(*ids.get(l).unwrap_or(&ids[0])));
            self.own.push(own);
            self.counts.push(lists.map(|s| s.len() as f64));
            for r in 0..rows {
                let (mut other, mut rest, mut ks, mut kd) =
                    (own, [0.0; LANES], [0.0; LANES], [0.0; LANES]);
                for (l, list) in lists.iter().enumerate() {
                    if let Some(s) = list.get(r) {
                        let (k, d) = graph.law(s);
                        (other[l], rest[l], ks[l], kd[l]) = (coordinate(s.other), s.rest, k, d);
                    }
                }
                self.other.push(other);
                self.rest.push(rest);
                self.ks.push(ks);
                self.kd.push(kd);
            }
        }
    }
}

/// Every colour's [`Stream`] for one colouring of the graph, laid out again when it is
/// coloured anew (at a detection that found pairs).
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Lanes {
    /// The colouring it was laid out for ([`Graph::colouring`]).
    built_for: Option<u64>,
    streams: Vec<Stream>,
}

impl Lanes {
    /// Lays out `graph`'s colours, unless it already has this colouring.
    pub(in crate::integrator) fn follow(&mut self, graph: &Graph) {
        if self.built_for == Some(graph.colouring) {
            return;
        }
        self.streams
            .resize_with(graph.colours.len(), Stream::default);
        for (stream, colour) in self.streams.iter_mut().zip(&graph.colours) {
            stream.fill(graph, colour);
        }
        self.built_for = Some(graph.colouring);
    }

    /// The inertia, drag and springs of particles `ids` at positions `x`, the `block`-th
    /// block of colour `colour` (`ids` its particles, at most [`LANES`]), into `out` (a lane
    /// past `ids` is left as it was), with `kernel`'s instructions.
    pub(in crate::integrator) fn sum(
        &self,
        kernel: Kernel,
        (local, x): (&Local<'_>, &[Vec3]),
        (colour, block, ids): (usize, usize, &[u32]),
        out: &mut [Block; LANES],
    ) {
        #[cfg(target_arch = "x86_64")]
        if kernel != Kernel::Portable {
            wide::sum(
                kernel,
                (local, x, &self.streams[colour], block),
                &mut out[..ids.len()],
            );
            return;
        }
        let _ = (kernel, colour, block);
        for (o, &i) in out.iter_mut().zip(ids) {
            *o = local.springs(i as usize, x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forces::spring::{Spring, SpringKind};
    use crate::integrator::vbd::detect::Detection;
    use crate::model::Model;
    use crate::particles::Particles;

    /// A number in [0, 1) from `k`, the same on every machine.
    fn jitter(k: usize) -> f64 {
        let h = (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        (h >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn every_kernel_sums_the_bits_of_one_particle_at_a_time() {
        // A jittered 9×9 sheet (colours whose last block is short), springs of three
        // reaches with their own rest lengths and coefficients, one spring between two
        // coincident particles (degenerate, skipped), one particle with no spring, drag.
        let n = 9;
        let mut p = Particles::default();
        for k in 0..n * n + 1 {
            let at = Vec3::new(
                (k % n) as f64 * 0.1 + 0.02 * jitter(3 * k),
                0.01 * jitter(3 * k + 1),
                (k / n) as f64 * 0.1 + 0.02 * jitter(3 * k + 2),
            );
            p.push(at, Vec3::zeros(), 0.01 + 0.01 * jitter(7 * k));
        }
        p.x[n + 1] = p.x[n];
        let id = |r: usize, c: usize| (r * n + c) as u32;
        let mut springs = Vec::new();
        for r in 0..n {
            for c in 0..n {
                for (dr, dc) in [(0, 1), (1, 0), (1, 1), (0, 2), (2, 0)] {
                    if r + dr < n && c + dc < n {
                        let k = springs.len();
                        springs.push(Spring {
                            i: id(r, c),
                            j: id(r + dr, c + dc),
                            rest: 0.1 * (1.0 + jitter(11 * k)),
                            ks: 50.0 + 100.0 * jitter(13 * k),
                            kd: 0.1 * jitter(17 * k),
                            kind: SpringKind::Other,
                        });
                    }
                }
            }
        }
        springs.push(Spring {
            i: n as u32,
            j: n as u32 + 1,
            rest: 0.1,
            ks: 80.0,
            kd: 0.05,
            kind: SpringKind::Other,
        });
        let model = Model {
            springs,
            drag: 0.003,
            mass_drag: 0.2,
            ..Model::default()
        };
        let graph = Graph::new(&model, &p);
        let start: Vec<Vec3> = (0..p.len())
            .map(|k| p.x[k] + Vec3::new(0.0, 0.003 * jitter(19 * k), 0.0))
            .collect();
        let target: Vec<Vec3> = start
            .iter()
            .map(|s| s + Vec3::new(0.0, -0.01, 0.0))
            .collect();
        let detection = Detection::default();
        let local = Local {
            model: &model,
            graph: &graph,
            detection: &detection,
            mass: &p.mass,
            start: &start,
            target: &target,
            dt: 1.0 / 60.0,
        };
        let mut lanes = Lanes::default();
        lanes.follow(&graph);
        let bits = |b: &Block| {
            let mut v: Vec<u64> = b.f.iter().map(|c| c.to_bits()).collect();
            v.extend(b.h.0.iter().map(|c| c.to_bits()));
            v
        };
        for kernel in Kernel::available() {
            let mut compared = 0;
            for (c, colour) in graph.colours.iter().enumerate() {
                for (block, ids) in colour.chunks(LANES).enumerate() {
                    let mut out = [Block::default(); LANES];
                    lanes.sum(kernel, (&local, &p.x), (c, block, ids), &mut out);
                    for (o, &i) in out.iter().zip(ids) {
                        let one = local.springs(i as usize, &p.x);
                        assert_eq!(bits(o), bits(&one), "{kernel}: particle {i}");
                        compared += 1;
                    }
                }
            }
            assert_eq!(compared, p.len(), "{kernel}: every particle summed once");
        }
    }
}
