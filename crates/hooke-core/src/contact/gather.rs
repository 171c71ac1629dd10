//! The contact phase's candidate pairs: the surfaces' primitives binned by their boxes in
//! hashed grids, and particle–triangle and edge–edge pairs gathered in fixed chunks, so
//! that the lists come out in the same order on any thread count.

use super::exclusion::Exclusion;
use super::grid::Grid;
use super::proximity::{point_triangle, segment_segment};
use crate::model::Model;
use crate::particles::Vec3;
use rayon::prelude::*;

/// A model's contact primitives, for gathering candidate pairs.
pub(super) struct Prims<'a> {
    pub(super) model: &'a Model,
    /// The pairs of one surface that its own structure holds apart: never candidates.
    pub(super) skip: &'a Exclusion,
    pub(super) owners: &'a [u32],
    pub(super) points: &'a [u32],
    pub(super) tris: &'a [[u32; 3]],
    pub(super) edges: &'a [[u32; 2]],
}

impl Prims<'_> {
    /// Replaces `point_tri` and `edge_edge` with the particle–triangle and edge–edge pairs of
    /// surfaces that collide nearer than `reach` at `x`, found through `bins` (binned at `x`
    /// with that reach): by particle, then by the particle's cells and triangle; by edge,
    /// then by the edge's cells and the other edge.
    pub(super) fn gather(
        &self,
        bins: &Bins,
        x: &[Vec3],
        reach: f64,
        scratch: &mut Vec<Vec<[u32; 2]>>,
        point_tri: &mut Vec<[u32; 2]>,
        edge_edge: &mut Vec<[u32; 2]>,
    ) {
        let (model, owners) = (self.model, self.owners);
        // Exact distances at the build: while no particle moves more than half a skin, no
        // pair farther apart than the thickness plus the skin can come within the thickness.
        let reach2 = reach * reach;
        let (tris, tri_box, tri_grid) = (self.tris, &bins.tri_box, &bins.tri_grid);
        let (edges, edge_box, edge_grid) = (self.edges, &bins.edge_box, &bins.edge_grid);
        let points = self.points;

        // Particle against triangle: the triangle's low cell is the particle's or one below.
        par_fill(points.len(), scratch, |i, out| {
            let p = points[i];
            let xp = x[p as usize];
            let c = tri_grid.cell_of(&xp);
            for d in 0..8 {
                let cell = [c[0] - (d & 1), c[1] - ((d >> 1) & 1), c[2] - ((d >> 2) & 1)];
                tri_grid.visit(cell, |t| {
                    let tri = tris[t as usize];
                    if !tri.contains(&p)
                        && inside(&xp, &tri_box[t as usize])
                        && !self.skip.skips_triangle(p, t)
                        && pair(model, owners, p, tri[0]).is_some()
                    {
                        let [a, b, c] = tri.map(|i| x[i as usize]);
                        let w = point_triangle(&xp, &a, &b, &c);
                        if (a * w[0] + b * w[1] + c * w[2] - xp).norm_squared() < reach2 {
                            out.push([p, t]);
                        }
                    }
                });
            }
        });
        point_tri.clear();
        append(point_tri, scratch);

        // Edge against edge: each pair once, from its lower edge, over the edge's own cell
        // and the 13 neighbours of one half-space (the other 13 see it from theirs).
        par_fill(edges.len(), scratch, |e, out| {
            let e = e as u32;
            let c = edge_grid.item_cell(e);
            let ee = edges[e as usize];
            for d in 13..27 {
                let cell = [c[0] + d % 3 - 1, c[1] + (d / 3) % 3 - 1, c[2] + d / 9 - 1];
                let own = d == 13;
                edge_grid.visit(cell, |f| {
                    let ef = edges[f as usize];
                    if (!own || f > e)
                        && !ef.contains(&ee[0])
                        && !ef.contains(&ee[1])
                        && overlap(&edge_box[e as usize], &edge_box[f as usize])
                        && !self.skip.skips_edges(e, f)
                        && pair(model, owners, ee[0], ef[0]).is_some()
                    {
                        let [a, b] = ee.map(|i| x[i as usize]);
                        let [c, d] = ef.map(|i| x[i as usize]);
                        let (s, t) = segment_segment(&a, &b, &c, &d);
                        if (a + (b - a) * s - c - (d - c) * t).norm_squared() < reach2 {
                            out.push([e, f]);
                        }
                    }
                });
            }
        });
        edge_edge.clear();
        append(edge_edge, scratch);
    }
}

/// Boxes of triangles and edges grown by a reach, and grids of them.
#[derive(Clone, Debug, Default)]
pub(super) struct Bins {
    pub(super) tri_box: Vec<(Vec3, Vec3)>,
    pub(super) edge_box: Vec<(Vec3, Vec3)>,
    pub(super) tri_grid: Grid,
    pub(super) edge_grid: Grid,
}

impl Bins {
    /// Bins the boxes of `tris` and `edges` at `x`, grown by `reach` (edges by half), in
    /// cells at least as large as the reach and every box.
    pub(super) fn bin(&mut self, x: &[Vec3], tris: &[[u32; 3]], edges: &[[u32; 2]], reach: f64) {
        let bounds = |ids: &[u32]| {
            ids.iter().fold(
                (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |(lo, hi), &i| (lo.inf(&x[i as usize]), hi.sup(&x[i as usize])),
            )
        };
        self.tri_box.clear();
        self.tri_box.extend(tris.iter().map(|t| {
            let (lo, hi) = bounds(t);
            (lo.add_scalar(-reach), hi.add_scalar(reach))
        }));
        self.edge_box.clear();
        self.edge_box.extend(edges.iter().map(|e| {
            let (lo, hi) = bounds(e);
            (lo.add_scalar(-0.5 * reach), hi.add_scalar(0.5 * reach))
        }));
        let cell = self
            .tri_box
            .iter()
            .chain(&self.edge_box)
            .map(|(lo, hi)| (hi - lo).max())
            .fold(reach, f64::max);
        self.tri_grid.build(cell, self.tri_box.iter().map(|b| b.0));
        self.edge_grid
            .build(cell, self.edge_box.iter().map(|b| b.0));
    }
}

/// Chunks of a parallel pass over candidates. Fixed, so that results come out in candidate
/// order whatever the thread count.
pub(super) const CHUNKS: usize = 8;
/// Fewer candidates than this are not worth a parallel pass.
pub(super) const PARALLEL_MIN: usize = 512;

/// Calls `f(i, out)` for every `i < n`, filling `bufs` (one per chunk of consecutive
/// indices, [`CHUNKS`] of them) in parallel; reading the buffers in order gives what a
/// sequential pass would have pushed.
pub(super) fn par_fill<U: Send>(
    n: usize,
    bufs: &mut Vec<Vec<U>>,
    f: impl Fn(usize, &mut Vec<U>) + Sync + Send,
) {
    bufs.resize_with(CHUNKS, Vec::new);
    for b in bufs.iter_mut() {
        b.clear();
    }
    if n < PARALLEL_MIN {
        for i in 0..n {
            f(i, &mut bufs[0]);
        }
        return;
    }
    let per = n.div_ceil(CHUNKS);
    bufs.par_iter_mut().enumerate().for_each(|(k, out)| {
        for i in (k * per).min(n)..((k + 1) * per).min(n) {
            f(i, out);
        }
    });
}

/// Appends the chunk buffers of [`par_fill`] to `dst` in order.
pub(super) fn append<U: Copy>(dst: &mut Vec<U>, bufs: &[Vec<U>]) {
    for b in bufs {
        dst.extend_from_slice(b);
    }
}

/// Whether `p` lies in the box.
pub(super) fn inside(p: &Vec3, (lo, hi): &(Vec3, Vec3)) -> bool {
    (0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k])
}
/// Whether two boxes overlap.
pub(super) fn overlap((a0, a1): &(Vec3, Vec3), (b0, b1): &(Vec3, Vec3)) -> bool {
    (0..3).all(|k| a0[k] <= b1[k] && b0[k] <= a1[k])
}
/// Whether particles `a` and `b` (both on active surfaces) collide: their surfaces differ
/// or share self-collision; with the pair's thickness (the larger) and friction (the mean).
pub(super) fn pair(model: &Model, surface_of: &[u32], a: u32, b: u32) -> Option<(f64, f64)> {
    let (sa, sb) = (surface_of[a as usize], surface_of[b as usize]);
    let (s, t) = (&model.surfaces[sa as usize], &model.surfaces[sb as usize]);
    if sa == sb && !s.self_collision {
        return None;
    }
    Some((
        s.thickness.max(t.thickness),
        0.5 * (s.friction + t.friction),
    ))
}
