//! The pairs a surface's own structure holds apart, which every contact detection skips
//! before any distance is measured (docs/physics.md §3.2 and §4.1, "What self-contact
//! skips"), as NVIDIA Newton's n-ring filter, Unreal Chaos's neighbour rings and Houdini
//! Vellum's rest distance do: block descent's and Newton's bounds, and the explicit
//! integrators' contact phase.
//!
//! Computed once, from the rest shape (the positions at the first detection), for pairs of
//! one surface, with `R` the radius and `R_n` the neighbours' (the thickness: a pair that
//! starts within it would be pushed apart at rest):
//!
//! * a particle `v` and a triangle `t` not holding it are skipped when their rest distance
//!   is within `R` and a corner of `t` is within `R` of `v` along the surface's edges, or
//!   within `R_n ≤ R` and a corner of `t` is `v`'s neighbour (one edge away, however long);
//! * two edges sharing no particle are skipped when their rest distance is within `R` and
//!   an end of one is within `R` of an end of the other along the edges, or within `R_n`
//!   and an end of one is the other's neighbour.
//!
//! The neighbours are for slivers: a corner of a thin triangle can lie a hair from the
//! triangle across its long side while both its edges there are long, and that pair, held
//! apart by the sliver's own springs, would otherwise be a contact from the first step.
//!
//! `R` is [`Model::self_contact_skip`], the search's reach between surfaces at rest. By
//! distance, not by rings: a pair farther apart at rest than the reach enters it only when
//! the surface folds, which is when it must be seen (at eight thicknesses, the shipped
//! curtain's 5 cm quads folded through each other in its wind). Along the edges, not
//! through space: two layers of one mesh near each other at rest (a garment's front and
//! back, a sheet that starts folded) are far apart along the surface and keep their
//! contacts beyond `R/2` of the fold, and two bodies never skip each other. On a regular
//! grid every pair within the reach is skipped, so its own neighbours never bound a flat
//! sheet's particles; on an irregular mesh the path along the edges is longer than the
//! straight distance, and some neighbours are still measured (13 % of them on a grid
//! jittered by 0.3 spacings with mixed diagonals). What can cross is a crease that brings a
//! skipped pair within a thickness.
//!
//! Each search is capped at [`MOST`] particles, nearest first; a cap only skips less (more
//! pairs measured), which the bounds' proof does not need.

use super::proximity::{point_triangle_distance, segment_distance};
#[cfg(doc)]
use crate::model::Model;
use crate::particles::Vec3;
use folds::Skipped;
pub(crate) use folds::{Folds, Plane, through};
use rayon::prelude::*;

/// At most this many particles reached by one search along the edges.
const MOST: usize = 2048;

/// The path bound along the edges as a multiple of the radius. Longer bounds skip more of
/// an irregular mesh's neighbours, but at 1.2 and 1.5 the finer of two triangulations of
/// one round cloth draped 4 % and 5 % less wide than the coarser (`tests/meshes.rs`).
const PATH: f64 = 1.0;

/// Sorted lists, one per particle (its skipped triangles) and one per edge (the skipped
/// edges below it: each pair once), in one array each.
#[derive(Clone, Debug, Default)]
pub(crate) struct Exclusion {
    triangle_start: Vec<u32>,
    triangles: Vec<u32>,
    edge_start: Vec<u32>,
    edges: Vec<u32>,
    /// The triangle pairs only a skipped pair could bring through each other.
    folds: Folds,
    /// The radius `R` the lists were built with, metres.
    radius: f64,
}

/// The surfaces whose pairs an exclusion lists: their triangles and edges (indexed as the
/// detection indexes them), and which particles lie on one that collides with itself (the
/// pairs of one that does not are never contacts, so nothing of it is listed, nor watched).
pub(crate) struct Surfaces<'a> {
    pub(crate) triangles: &'a [[u32; 3]],
    pub(crate) edges: &'a [[u32; 2]],
    pub(crate) self_colliding: &'a (dyn Fn(u32) -> bool + Sync),
    /// Whether any pair of them can touch (none when no surface collides with itself and
    /// there is only one): then nothing is listed.
    pub(crate) self_pairs: bool,
}

/// Per particle: its active surface's triangles and edges that hold it, and its neighbours
/// along the edges with the edges' rest lengths.
struct Adjacency {
    triangles: Vec<Vec<u32>>,
    edges: Vec<Vec<u32>>,
    neighbours: Vec<Vec<(u32, f64)>>,
}

impl Adjacency {
    fn new(topo: &Surfaces, rest: &[Vec3]) -> Self {
        let n = rest.len();
        let mut a = Self {
            triangles: vec![Vec::new(); n],
            edges: vec![Vec::new(); n],
            neighbours: vec![Vec::new(); n],
        };
        for (t, tri) in topo.triangles.iter().enumerate() {
            for &i in tri {
                a.triangles[i as usize].push(t as u32);
            }
        }
        for (e, [i, j]) in topo.edges.iter().enumerate() {
            let length = (rest[*i as usize] - rest[*j as usize]).norm();
            a.edges[*i as usize].push(e as u32);
            a.edges[*j as usize].push(e as u32);
            a.neighbours[*i as usize].push((*j, length));
            a.neighbours[*j as usize].push((*i, length));
        }
        a
    }
}

/// A search along the edges from some particles, reused from one search to the next.
struct Paths {
    /// Per particle: the search that reached it last, and its distance then.
    mark: Vec<u32>,
    distance: Vec<f64>,
    generation: u32,
    /// The particles reached by the current search, in the order they were settled.
    reached: Vec<u32>,
    /// Primitives already seen by the current search (by their index), and their marks.
    seen: Vec<u32>,
    heap: std::collections::BinaryHeap<(std::cmp::Reverse<Length>, u32)>,
}

/// A non-negative length, ordered (never NaN: sums of rest lengths).
#[derive(Clone, Copy, PartialEq)]
struct Length(f64);
impl Eq for Length {}
impl PartialOrd for Length {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Length {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

impl Paths {
    fn new(particles: usize, primitives: usize) -> Self {
        Self {
            mark: vec![0; particles],
            distance: vec![0.0; particles],
            generation: 0,
            reached: Vec::new(),
            seen: vec![0; primitives],
            heap: std::collections::BinaryHeap::new(),
        }
    }

    /// Every particle within `bound` of `from` along the edges (at most [`MOST`], nearest
    /// first), into `reached`; ties are settled by index, so the result is fixed.
    fn search(&mut self, adj: &Adjacency, from: &[u32], bound: f64) {
        self.generation += 1;
        let g = self.generation;
        self.reached.clear();
        self.heap.clear();
        for &v in from {
            self.heap.push((std::cmp::Reverse(Length(0.0)), v));
        }
        while let Some((std::cmp::Reverse(Length(d)), v)) = self.heap.pop() {
            let k = v as usize;
            if self.mark[k] == g && self.distance[k] <= d {
                continue;
            }
            self.mark[k] = g;
            self.distance[k] = d;
            self.reached.push(v);
            if self.reached.len() >= MOST {
                break;
            }
            for &(w, length) in &adj.neighbours[k] {
                let e = d + length;
                let seen = self.mark[w as usize] == g;
                if e <= bound && (!seen || e < self.distance[w as usize]) {
                    self.heap.push((std::cmp::Reverse(Length(e)), w));
                }
            }
        }
    }

    /// Marks primitive `k` as seen by this search, saying whether it was new.
    fn first_sight(&mut self, k: u32) -> bool {
        let m = &mut self.seen[k as usize];
        let new = *m != self.generation;
        *m = self.generation;
        new
    }
}

/// List `i` of lists in one array `all` with their starts (empty without lists).
fn list<'a>(start: &[u32], all: &'a [u32], i: usize) -> &'a [u32] {
    match (start.get(i), start.get(i + 1)) {
        (Some(&a), Some(&b)) => &all[a as usize..b as usize],
        _ => &[],
    }
}

/// Whether `k` is in list `i` (none without lists: an exclusion that skips nothing).
#[inline]
fn listed(start: &[u32], all: &[u32], i: u32, k: u32) -> bool {
    list(start, all, i as usize).binary_search(&k).is_ok()
}

/// Each pair of a symmetric relation given as `lists` (`f` in `lists[e]`, or `e` in
/// `lists[f]`) once, under its larger index: the edges' lists hold most pairs from both
/// sides, and one lookup then answers for the pair.
fn once(lists: Vec<Vec<u32>>) -> Vec<Vec<u32>> {
    let mut out = vec![Vec::new(); lists.len()];
    for (e, list) in lists.into_iter().enumerate() {
        let e = e as u32;
        for f in list {
            out[e.max(f) as usize].push(e.min(f));
        }
    }
    for list in &mut out {
        list.sort_unstable();
        list.dedup();
        list.shrink_to_fit();
    }
    out
}

/// Lists in one array and their starts.
fn flatten(lists: Vec<Vec<u32>>) -> (Vec<u32>, Vec<u32>) {
    let mut start = Vec::with_capacity(lists.len() + 1);
    start.push(0u32);
    let mut all = Vec::with_capacity(lists.iter().map(Vec::len).sum());
    for list in lists {
        all.extend(list);
        start.push(all.len() as u32);
    }
    (start, all)
}

impl Exclusion {
    /// An exclusion that skips nothing, for `particles` particles and `edges` edges.
    fn none(particles: usize, edges: usize) -> Self {
        Self {
            triangle_start: vec![0; particles + 1],
            edge_start: vec![0; edges + 1],
            ..Self::default()
        }
    }

    /// The lists for `surfaces` at rest positions `rest`, with radius `radius` and, for pairs
    /// one edge apart, `near` (at most `radius`: the thickness, within which a pair would be
    /// pushed apart at rest; a fine mesh drapes otherwise if more are skipped); no pair with
    /// a particle that `pinned` names is skipped (a keyed pin is moved by its keys, not held
    /// by its springs, and may sweep through its own neighbourhood).
    pub(crate) fn new(
        surfaces: &Surfaces,
        rest: &[Vec3],
        (radius, near): (f64, f64),
        pinned: &(dyn Fn(u32) -> bool + Sync),
    ) -> Self {
        let n = rest.len();
        if !surfaces.self_pairs {
            return Self::none(n, surfaces.edges.len());
        }
        let adj = Adjacency::new(surfaces, rest);
        let path = PATH * radius;
        // Each worker's search marks are as long as the mesh: four sets of them a thread,
        // not one per split of a large mesh (the lists do not depend on the splits).
        let splits = 4 * rayon::current_num_threads();
        let per_split = |len: usize| len.div_ceil(splits).max(256);
        let triangles: Vec<Vec<u32>> = (0..n as u32)
            .into_par_iter()
            .with_min_len(per_split(n))
            .map_init(
                || Paths::new(n, surfaces.triangles.len()),
                |paths, v| {
                    if !(surfaces.self_colliding)(v) || pinned(v) {
                        return Vec::new();
                    }
                    paths.search(&adj, &[v], path);
                    let p = &rest[v as usize];
                    let mut out = Vec::new();
                    // Taken while `first_sight` marks the search, and given back for the next.
                    let along = std::mem::take(&mut paths.reached);
                    let next = adj.neighbours[v as usize].iter().map(|&(w, _)| (w, near));
                    for (w, within) in along.iter().map(|&w| (w, radius)).chain(next) {
                        for &t in &adj.triangles[w as usize] {
                            let tri = surfaces.triangles[t as usize];
                            if paths.first_sight(t)
                                && !tri.contains(&v)
                                && !tri.iter().any(|&i| pinned(i))
                                && point_triangle_distance(p, tri.map(|i| &rest[i as usize]))
                                    <= within
                            {
                                out.push(t);
                            }
                        }
                    }
                    paths.reached = along;
                    out.sort_unstable();
                    out
                },
            )
            .collect();
        let edges: Vec<Vec<u32>> = (0..surfaces.edges.len())
            .into_par_iter()
            .with_min_len(per_split(surfaces.edges.len()))
            .map_init(
                || Paths::new(n, surfaces.edges.len()),
                |paths, e| {
                    let [a, b] = surfaces.edges[e];
                    if !(surfaces.self_colliding)(a) || pinned(a) || pinned(b) {
                        return Vec::new();
                    }
                    paths.search(&adj, &[a, b], path);
                    let mut out = Vec::new();
                    let along = std::mem::take(&mut paths.reached);
                    let next = [a, b]
                        .into_iter()
                        .flat_map(|k| adj.neighbours[k as usize].iter().map(|&(w, _)| (w, near)));
                    for (w, within) in along.iter().map(|&w| (w, radius)).chain(next) {
                        for &f in &adj.edges[w as usize] {
                            let [c, d] = surfaces.edges[f as usize];
                            let ends = [a, b, c, d].map(|i| &rest[i as usize]);
                            if paths.first_sight(f)
                                && !pinned(c)
                                && !pinned(d)
                                && ![c, d].contains(&a)
                                && ![c, d].contains(&b)
                                && segment_distance(ends) <= within
                            {
                                out.push(f);
                            }
                        }
                    }
                    paths.reached = along;
                    out.sort_unstable();
                    out
                },
            )
            .collect();
        let (triangle_start, triangles) = flatten(triangles);
        let (edge_start, edges) = flatten(once(edges));
        let skipped = Skipped {
            triangle_start: &triangle_start,
            triangles: &triangles,
            edge_start: &edge_start,
            edges: &edges,
        };
        let folds = Folds::new(surfaces.triangles, surfaces.edges, &adj.triangles, &skipped);
        Self {
            triangle_start,
            triangles,
            edge_start,
            edges,
            folds,
            radius,
        }
    }

    /// The watch on the triangle pairs that only a skipped pair could bring through each
    /// other (`folds.rs`).
    pub(crate) fn folds(&self) -> &Folds {
        &self.folds
    }

    /// The radius `R` within which pairs at rest are skipped, metres.
    pub(crate) fn radius(&self) -> f64 {
        self.radius
    }

    /// Whether the pair of particle `v` and triangle `t` is skipped.
    #[inline]
    pub(crate) fn skips_triangle(&self, v: u32, t: u32) -> bool {
        listed(&self.triangle_start, &self.triangles, v, t)
    }

    /// Whether the pair of edges `e` and `f` is skipped: either is in the other's set (the
    /// pair is listed once, under the larger index).
    #[inline]
    pub(crate) fn skips_edges(&self, e: u32, f: u32) -> bool {
        listed(&self.edge_start, &self.edges, e.max(f), e.min(f))
    }

    /// The triangles skipped with particle `v` ([`Exclusion::skips_triangle`]), ascending.
    pub(crate) fn triangles_of(&self, v: u32) -> &[u32] {
        list(&self.triangle_start, &self.triangles, v as usize)
    }

    /// The edges below `e` skipped with it ([`Exclusion::skips_edges`]), ascending.
    pub(crate) fn edges_below(&self, e: u32) -> &[u32] {
        list(&self.edge_start, &self.edges, e as usize)
    }

    /// How many pairs are listed.
    #[cfg(test)]
    fn len(&self) -> usize {
        self.triangles.len() + self.edges.len()
    }
}

mod folds;
#[cfg(test)]
pub(crate) mod tests;
