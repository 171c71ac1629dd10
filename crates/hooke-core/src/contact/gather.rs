//! The contact phase's candidate pairs: the surfaces' primitives binned by their boxes in
//! hashed grids, and particle–triangle and edge–edge pairs gathered in fixed chunks, so
//! that the lists come out in the same order on any thread count.

use super::crowding::{Caps, Count, Crowded};
use super::exclusion::Exclusion;
use super::grid::Grid;
use super::proximity::{feature_gap, point_triangle, segment_segment};
use super::stencil::Rule;
use crate::collider::Feature;
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
    /// then by the edge's cells and the other edge. More pairs of either kind than `caps`
    /// allow are [`Crowded`]: the lists are then left empty.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn gather(
        &self,
        bins: &Bins,
        x: &[Vec3],
        reach: f64,
        caps: Caps,
        scratch: &mut Vec<Vec<[u32; 2]>>,
        point_tri: &mut Vec<[u32; 2]>,
        edge_edge: &mut Vec<[u32; 2]>,
    ) -> Result<(), Crowded> {
        let (model, owners) = (self.model, self.owners);
        // Exact distances at the build: while no particle moves more than half a skin, no
        // pair farther apart than the thickness plus the skin can come within the thickness.
        let reach2 = reach * reach;
        let (tris, tri_box, tri_grid) = (self.tris, &bins.tri_box, &bins.tri_grid);
        let (edges, edge_box, edge_grid) = (self.edges, &bins.edge_box, &bins.edge_grid);
        let points = self.points;

        point_tri.clear();
        edge_edge.clear();

        // Particle against triangle: the triangle's low cell is the particle's or one below.
        let count = Count::new(caps.point_tri);
        par_fill(points.len(), scratch, |i, out| {
            if count.full() {
                return;
            }
            let before = out.len();
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
            count.add(out.len() - before);
        });
        count.verdict()?;
        append(point_tri, scratch);

        // Edge against edge: each pair once, from its lower edge, over the edge's own cell
        // and the 13 neighbours of one half-space (the other 13 see it from theirs).
        let count = Count::new(caps.edge_edge);
        par_fill(edges.len(), scratch, |e, out| {
            if count.full() {
                return;
            }
            let before = out.len();
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
            count.add(out.len() - before);
        });
        if let Err(crowded) = count.verdict() {
            point_tri.clear();
            return Err(crowded);
        }
        append(edge_edge, scratch);
        Ok(())
    }
}

/// A triangle near a collider feature.
#[derive(Clone, Copy, Debug)]
pub(super) struct FeaturePair {
    pub(super) tri: u32,
    pub(super) feature: Feature,
    pub(super) rule: Rule,
    /// The collider's index (for its velocity).
    pub(super) collider: u16,
}

/// Replaces `pairs` with the collider feature–triangle pairs nearer than `reach` at `x`,
/// found through `bins` (binned at `x` with that reach), by triangle; `features` is the
/// colliders' features near the triangles, kept for its buffer.
pub(super) fn feature_pairs(
    model: &Model,
    (bins, tris): (&Bins, &[[u32; 3]]),
    x: &[Vec3],
    reach: f64,
    (features, pairs): (&mut Vec<(Feature, Rule, u16)>, &mut Vec<FeaturePair>),
) {
    pairs.clear();
    features.clear();
    if tris.is_empty() {
        return;
    }
    let (lo, hi) = bins
        .tri_box
        .iter()
        .fold((bins.tri_box[0].0, bins.tri_box[0].1), |(lo, hi), b| {
            (lo.inf(&b.0), hi.sup(&b.1))
        });
    for (k, slot) in model.colliders.iter().enumerate() {
        if !slot.shape.has_features() {
            continue;
        }
        let rule = Rule::of(&slot.response);
        slot.shape
            .features(&lo, &hi, &mut |f| features.push((f, rule, k as u16)));
    }
    for &(feature, rule, collider) in features.iter() {
        let (flo, fhi) = feature.bounds();
        let (c0, c1) = (bins.tri_grid.cell_of(&flo), bins.tri_grid.cell_of(&fhi));
        for i in c0[0] - 1..=c1[0] {
            for j in c0[1] - 1..=c1[1] {
                for k in c0[2] - 1..=c1[2] {
                    bins.tri_grid.visit([i, j, k], |t| {
                        let b = &bins.tri_box[t as usize];
                        if overlap(b, &(flo, fhi))
                            && feature_gap(&feature, &tris[t as usize], x, reach).is_some()
                        {
                            pairs.push(FeaturePair {
                                tri: t,
                                feature,
                                rule,
                                collider,
                            });
                        }
                    });
                }
            }
        }
    }
    // One order whatever the features' order: by triangle, then as found.
    pairs.sort_by_key(|p| p.tri);
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
