//! The pairs a surface's own structure holds apart, which block descent's detection skips
//! before any distance is measured (docs/physics.md §4.1, "What self-contact skips"), as
//! NVIDIA Newton's n-ring filter, Unreal Chaos's neighbour rings and Houdini Vellum's rest
//! distance do.
//!
//! Computed once, from the rest shape (the positions at the first detection), for pairs of
//! one surface, with `R` the radius:
//!
//! * a particle `v` and a triangle `t` not holding it are skipped when their rest distance
//!   is within `R` and a corner of `t` is within `R` of `v` along the surface's edges;
//! * two edges sharing no particle are skipped when their rest distance is within `R` and
//!   an end of one is within `R` of an end of the other along the edges.
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

use super::topology::{Topology, point_triangle_distance, segment_distance};
#[cfg(doc)]
use crate::model::Model;
use crate::particles::Vec3;
use rayon::prelude::*;

/// At most this many particles reached by one search along the edges.
const MOST: usize = 2048;

/// The path bound along the edges as a multiple of the radius. Longer bounds skip more of
/// an irregular mesh's neighbours, but at 1.2 and 1.5 the finer of two triangulations of
/// one round cloth draped 4 % and 5 % less wide than the coarser (`tests/meshes.rs`).
const PATH: f64 = 1.0;

/// Sorted lists, one per particle (triangles) and one per edge (edges), in one array each.
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Exclusion {
    triangle_start: Vec<u32>,
    triangles: Vec<u32>,
    edge_start: Vec<u32>,
    edges: Vec<u32>,
}

/// Per particle: its active surface's triangles and edges that hold it, and its neighbours
/// along the edges with the edges' rest lengths.
struct Adjacency {
    triangles: Vec<Vec<u32>>,
    edges: Vec<Vec<u32>>,
    neighbours: Vec<Vec<(u32, f64)>>,
}

impl Adjacency {
    fn new(topo: &Topology, rest: &[Vec3]) -> Self {
        let n = rest.len();
        let mut a = Self {
            triangles: vec![Vec::new(); n],
            edges: vec![Vec::new(); n],
            neighbours: vec![Vec::new(); n],
        };
        for (t, (tri, _)) in topo.triangles.iter().enumerate() {
            for &i in tri {
                a.triangles[i as usize].push(t as u32);
            }
        }
        for (e, ([i, j], _)) in topo.edges.iter().enumerate() {
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

/// Whether `k` is in list `i` (none without lists: an exclusion that skips nothing).
#[inline]
fn listed(start: &[u32], all: &[u32], i: u32, k: u32) -> bool {
    let i = i as usize;
    match (start.get(i), start.get(i + 1)) {
        (Some(&a), Some(&b)) => all[a as usize..b as usize].binary_search(&k).is_ok(),
        _ => false,
    }
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
    /// The lists for the surfaces of `topo` at rest positions `rest`, with radius `radius`;
    /// no pair with a particle that `pinned` names is skipped (a keyed pin is moved by its
    /// keys, not held by its springs, and may sweep through its own neighbourhood).
    pub(in crate::integrator) fn new(
        topo: &Topology,
        rest: &[Vec3],
        radius: f64,
        pinned: &(dyn Fn(u32) -> bool + Sync),
    ) -> Self {
        let n = rest.len();
        if !topo.self_pairs {
            return Self {
                triangle_start: vec![0; n + 1],
                edge_start: vec![0; topo.edges.len() + 1],
                ..Self::default()
            };
        }
        let adj = Adjacency::new(topo, rest);
        let path = PATH * radius;
        // Each worker's search marks are as long as the mesh: at most 64 sets of them, not
        // one per split of a large mesh.
        let per_split = |len: usize| len.div_ceil(64).max(256);
        let triangles: Vec<Vec<u32>> = (0..n as u32)
            .into_par_iter()
            .with_min_len(per_split(n))
            .map_init(
                || Paths::new(n, topo.triangles.len()),
                |paths, v| {
                    if topo.surface[v as usize] == u16::MAX || pinned(v) {
                        return Vec::new();
                    }
                    paths.search(&adj, &[v], path);
                    let p = &rest[v as usize];
                    let mut out = Vec::new();
                    for k in 0..paths.reached.len() {
                        let w = paths.reached[k];
                        for &t in &adj.triangles[w as usize] {
                            let tri = topo.triangles[t as usize].0;
                            if paths.first_sight(t)
                                && !tri.contains(&v)
                                && !tri.iter().any(|&i| pinned(i))
                                && point_triangle_distance(p, tri.map(|i| &rest[i as usize]))
                                    <= radius
                            {
                                out.push(t);
                            }
                        }
                    }
                    out.sort_unstable();
                    out
                },
            )
            .collect();
        let edges: Vec<Vec<u32>> = (0..topo.edges.len())
            .into_par_iter()
            .with_min_len(per_split(topo.edges.len()))
            .map_init(
                || Paths::new(n, topo.edges.len()),
                |paths, e| {
                    let [a, b] = topo.edges[e].0;
                    if pinned(a) || pinned(b) {
                        return Vec::new();
                    }
                    paths.search(&adj, &[a, b], path);
                    let mut out = Vec::new();
                    for k in 0..paths.reached.len() {
                        let w = paths.reached[k];
                        for &f in &adj.edges[w as usize] {
                            let [c, d] = topo.edges[f as usize].0;
                            let ends = [a, b, c, d].map(|i| &rest[i as usize]);
                            if paths.first_sight(f)
                                && !pinned(c)
                                && !pinned(d)
                                && ![c, d].contains(&a)
                                && ![c, d].contains(&b)
                                && segment_distance(ends) <= radius
                            {
                                out.push(f);
                            }
                        }
                    }
                    out.sort_unstable();
                    out
                },
            )
            .collect();
        let (triangle_start, triangles) = flatten(triangles);
        let (edge_start, edges) = flatten(edges);
        Self {
            triangle_start,
            triangles,
            edge_start,
            edges,
        }
    }

    /// Whether the pair of particle `v` and triangle `t` is skipped.
    #[inline]
    pub(in crate::integrator) fn skips_triangle(&self, v: u32, t: u32) -> bool {
        listed(&self.triangle_start, &self.triangles, v, t)
    }

    /// Whether the pair of edges `e` and `f` is skipped: either is in the other's set.
    #[inline]
    pub(in crate::integrator) fn skips_edges(&self, e: u32, f: u32) -> bool {
        listed(&self.edge_start, &self.edges, e, f) || listed(&self.edge_start, &self.edges, f, e)
    }

    /// How many pairs are listed (an edge pair once or twice).
    #[cfg(test)]
    fn len(&self) -> usize {
        self.triangles.len() + self.edges.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::grid::Grid;
    use crate::integrator::vbd::candidates::search;
    use crate::model::Model;
    use crate::model::surface::Surface;

    /// A fixed pseudo-random sequence in `[-0.5, 0.5)`.
    fn noise(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// An `n`×`n` sheet of spacing `s` in the x-z plane, its quads split along a diagonal
    /// that `flip` chooses, its points placed by `at(i, j)`; thickness `h`.
    fn sheet(
        n: usize,
        h: f64,
        mut flip: impl FnMut(usize, usize) -> bool,
        mut at: impl FnMut(usize, usize) -> Vec3,
    ) -> (Model, Vec<Vec3>) {
        let mut x = Vec::new();
        for j in 0..n {
            for i in 0..n {
                x.push(at(i, j));
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u32;
                let (b, c, d) = (a + 1, a + n as u32, a + n as u32 + 1);
                if flip(i, j) {
                    triangles.extend([[a, b, c], [b, d, c]]);
                } else {
                    triangles.extend([[a, b, d], [a, d, c]]);
                }
            }
        }
        let model = Model {
            surfaces: vec![Surface {
                particles: 0..n * n,
                triangles,
                thickness: h,
                self_collision: true,
                friction: 0.0,
            }],
            ..Model::default()
        };
        (model, x)
    }

    /// The pairs the detection's search finds within `reach` at `x`, with and without the
    /// exclusion built at `x` for that reach.
    fn pairs(model: &Model, x: &[Vec3], reach: f64) -> (usize, usize, Exclusion) {
        let topo = Topology::new(model, x.len());
        let skip = Exclusion::new(&topo, x, reach, &|_| false);
        let count = |skip: &Exclusion| {
            let (a, b) = search(
                (&topo, skip),
                x,
                reach,
                (&mut Grid::default(), &mut Grid::default()),
            );
            a.len() + b.len()
        };
        (count(&Exclusion::default()), count(&skip), skip)
    }

    /// On a flat sheet at rest the exclusion leaves no pair within the reach of a grid at
    /// the 128² drape's reach (just over a spacing), and at most a fifth of them where paths
    /// along the edges are longer than the straight distance: a grid whose reach spans three
    /// spacings, its diagonals alternating (2.5 % measured), and one with its diagonals
    /// mixed and its points jittered by up to 0.3 spacings (13 %).
    #[test]
    fn a_flat_sheet_at_rest_leaves_no_pair_of_its_own_to_measure() {
        let s = 0.0126;
        let regular = sheet(
            24,
            s / 4.0,
            |_, _| false,
            |i, j| Vec3::new(i as f64 * s, 0.0, j as f64 * s),
        );
        let mut jitter = noise(7);
        let mut coin = noise(11);
        let irregular = sheet(
            24,
            s / 4.0,
            |_, _| coin() < 0.0,
            |i, j| {
                Vec3::new(
                    (i as f64 + 0.6 * jitter()) * s,
                    0.0,
                    (j as f64 + 0.6 * jitter()) * s,
                )
            },
        );
        let fine = sheet(
            24,
            0.75 * s,
            |i, j| (i + j) % 2 == 0,
            |i, j| Vec3::new(i as f64 * s, 0.0, j as f64 * s),
        );
        for (name, (model, x), reach) in [
            ("regular", regular, 1.016 * s),
            ("irregular", irregular, 1.016 * s),
            ("fine", fine, 3.0 * s),
        ] {
            let (all, left, skip) = pairs(&model, &x, reach);
            assert!(all > 1000, "{name}: {all} pairs without the exclusion");
            let most = if name == "regular" { 0 } else { all / 5 };
            assert!(
                left <= most,
                "{name}: {left} of {all} pairs left ({} skipped)",
                skip.len()
            );
        }
    }

    /// Connection, not distance: a sheet folded over itself keeps every pair across its
    /// layers beyond the exclusion's reach of the fold, and two separate sheets lying on
    /// each other skip nothing between them.
    #[test]
    fn layers_that_are_not_neighbours_along_the_surface_still_collide() {
        let (n, s) = (20usize, 0.01);
        let gap = 0.6 * s;
        let reach = 1.2 * s;
        // The far half turned back over the near half, `gap` above it.
        let (model, x) = sheet(
            n,
            s / 4.0,
            |_, _| false,
            |i, j| {
                if j < n / 2 {
                    Vec3::new(i as f64 * s, 0.0, j as f64 * s)
                } else {
                    Vec3::new(i as f64 * s, gap, (n - 1 - j) as f64 * s)
                }
            },
        );
        let topo = Topology::new(&model, x.len());
        let skip = Exclusion::new(&topo, &x, reach, &|_| false);
        let (points, _) = search(
            (&topo, &skip),
            &x,
            reach,
            (&mut Grid::default(), &mut Grid::default()),
        );
        // Along the sheet, particle row `j` of the lower layer is `2 (n/2 - 1 - j)` spacings
        // and the fold's height from the upper layer's point above it: beyond the path
        // bound, each must still meet the layer above.
        for j in 0..n / 2 {
            let along = 2.0 * (n / 2 - 1 - j) as f64 * s + gap;
            if along <= PATH * reach + 2.0 * s {
                continue;
            }
            for i in 0..n {
                let v = (j * n + i) as u32;
                let above = points.iter().any(|c| {
                    c.a == v
                        && topo.triangles[c.b as usize]
                            .0
                            .iter()
                            .all(|&k| k as usize >= n * n / 2)
                });
                assert!(
                    above,
                    "particle {v} (row {j}) lost its pair with the layer above"
                );
            }
        }
        // Two sheets, one `gap` above the other: different surfaces, nothing skipped.
        let (mut two, below) = sheet(
            n,
            s / 4.0,
            |_, _| false,
            |i, j| Vec3::new(i as f64 * s, 0.0, j as f64 * s),
        );
        let mut x = below.clone();
        x.extend(below.iter().map(|p| p + Vec3::new(0.0, gap, 0.0)));
        let mut upper = two.surfaces[0].clone();
        let shift = (n * n) as u32;
        upper.particles = n * n..2 * n * n;
        upper
            .triangles
            .iter_mut()
            .flatten()
            .for_each(|k| *k += shift);
        two.surfaces.push(upper);
        let topo = Topology::new(&two, x.len());
        let skip = Exclusion::new(&topo, &x, reach, &|_| false);
        for v in 0..(n * n) as u32 {
            for (t, (tri, surface)) in topo.triangles.iter().enumerate() {
                if *surface == 1 {
                    assert!(!skip.skips_triangle(v, t as u32), "{v} skips {tri:?}");
                }
            }
        }
    }
}
