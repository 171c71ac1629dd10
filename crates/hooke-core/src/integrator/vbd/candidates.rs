//! Surface pairs kept between detections (a Verlet list with travel budgets, as the contact
//! phase keeps its own, docs/physics.md §3.3 and §4.1): every point–triangle and edge–edge
//! pair of the surfaces within `reach + skin` at a build, with the distance at its last
//! exact test. Each surface particle's *travel* — the path its position took relative to the
//! surfaces' mean motion, summed over the detections since the build — bounds how far any
//! gap can have closed:
//!
//! * a listed pair last measured at `d` while its particles' travel summed to `T₀` is still
//!   at least `d - (T - T₀)` apart when they sum to `T`, and is not tested again while that
//!   is at least the reach: what it would give is known (beyond the reach, unseen);
//! * a pair left out of the list was at least `reach + skin` apart at the build, and its
//!   gap has closed by at most twice the largest travel since: the list holds every pair
//!   within the reach while the largest travel stays under half the skin, and is built
//!   again when it does not (or when the reach grows past what it was built for).
//!
//! So a detection finds exactly the pairs within its reach, with their exact distances, as
//! a search over every pair would: only the order of the list (the build's, fixed by the
//! positions then) differs, and no thread count changes it.

use super::cells::{bin, bounds_of, boxes_within, by_cell, concatenate, within};
use super::topology::Topology;
use crate::contact::exclusion::Exclusion;
use crate::contact::grid::{Cell, Grid};
use crate::contact::proximity::{point_triangle_distance, segment_distance};
use crate::particles::Vec3;
use rayon::prelude::*;

/// The skin of a build, as a share of the reach it serves.
pub(in crate::integrator) const SKIN: f64 = 1.0;

/// One part of the list: its pairs in the search's order, in runs that share their first
/// primitive (a particle, or an edge), each pair as its second primitive (a triangle, or an
/// earlier edge) and its bound: the distance at its last exact test plus its particles'
/// travel summed then, rounded down to single precision. The list is block descent's
/// largest structure (1.3 million pairs on the flat 128² cloth): a pair takes 8 bytes, and
/// a run (some twenty pairs) 8 more.
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Part {
    /// Per run: its first primitive, and where its pairs end in `pairs`.
    runs: Vec<(u32, u32)>,
    pairs: Vec<Listed>,
}

/// A listed pair's second primitive and bound (see [`Part`]).
#[derive(Clone, Copy, Debug)]
struct Listed {
    b: u32,
    bound: f32,
}

/// `x` rounded down to single precision: a bound that is never above what it stands for,
/// so that every skip it proves is one the double-precision sum would prove. Without a
/// branch: whether rounding to nearest went up is a coin toss, and a mispredicted branch
/// per pair cost cloth-pile's detection a tenth of its time.
#[inline]
fn down(x: f64) -> f32 {
    debug_assert!(
        x >= 0.0 || x.is_nan(),
        "bounds are distances plus travel: {x}"
    );
    let f = x as f32;
    // One unit in the last place down when rounding went up (the largest finite float
    // below infinity); never for a NaN, which compares false.
    f32::from_bits(f.to_bits() - u32::from(f64::from(f) > x))
}

impl Part {
    /// Appends pair `(a, b)` at bound `bound`.
    #[inline]
    fn push(&mut self, a: u32, b: u32, bound: f64) {
        match self.runs.last_mut() {
            Some((first, end)) if *first == a => *end += 1,
            _ => self.runs.push((a, self.pairs.len() as u32 + 1)),
        }
        self.pairs.push(Listed {
            b,
            bound: down(bound),
        });
    }

    /// Drops the slack of the part's growth: the parts are the pair list's memory.
    fn shrink(&mut self) {
        self.runs.shrink_to_fit();
        self.pairs.shrink_to_fit();
    }

    /// The pairs as `(a, b, bound)`, in order.
    #[cfg(test)]
    fn iter(&self) -> impl Iterator<Item = (u32, u32, f32)> + '_ {
        let mut begin = 0;
        self.runs.iter().flat_map(move |&(a, end)| {
            let run = &self.pairs[begin as usize..end as usize];
            begin = end;
            run.iter().map(move |p| (a, p.b, p.bound))
        })
    }
}

/// Rounding allowed for in a pair's bound, relative to it: `bound - travel` is the
/// distance less the travel since, up to a few units in the last place of the larger.
const ROUNDING: f64 = 1e-12;

/// The list and the travel since its build.
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Candidates {
    /// The reach the list holds every pair within, at the build.
    built: f64,
    /// Whether a list was built for the current topology.
    valid: bool,
    /// Per particle: travel since the build, relative to the surfaces' mean motion.
    travel: Vec<f64>,
    /// The largest of it.
    most: f64,
    /// Positions and their surfaces' mean at the last detection.
    last: Vec<Vec3>,
    last_mean: Vec3,
    /// The pairs in parts of the build's search, in its order.
    point_tri: Vec<Part>,
    edge_edge: Vec<Part>,
}

/// The mean of the surface particles' positions (zero without any).
fn surface_mean(topo: &Topology, x: &[Vec3]) -> Vec3 {
    let (mut sum, mut count) = (Vec3::zeros(), 0usize);
    for (i, p) in x.iter().enumerate() {
        if topo.surface[i] != u16::MAX {
            sum += p;
            count += 1;
        }
    }
    if count == 0 { sum } else { sum / count as f64 }
}

impl Candidates {
    /// Adds the motion since the last detection to each surface particle's travel.
    pub(in crate::integrator) fn update(&mut self, topo: &Topology, x: &[Vec3], reach: f64) {
        let mean = surface_mean(topo, x);
        if !self.valid || self.last.len() != x.len() || !reach.is_finite() {
            self.valid = false;
            self.last_mean = mean;
            self.last.clear();
            self.last.extend_from_slice(x);
            return;
        }
        let shift = mean - self.last_mean;
        let mut most = self.most;
        for (i, (t, (p, q))) in self
            .travel
            .iter_mut()
            .zip(x.iter().zip(&self.last))
            .enumerate()
        {
            if topo.surface[i] != u16::MAX {
                *t += (p - q - shift).norm();
                most = most.max(*t);
            }
        }
        self.most = most;
        self.last.copy_from_slice(x);
        self.last_mean = mean;
    }

    /// Whether the list may miss a pair within `reach` (see the module docs).
    pub(in crate::integrator) fn stale(&self, reach: f64) -> bool {
        !self.valid || 2.0 * self.most >= self.built - reach
    }

    /// Frees the list (the pairs, not the travel): a build follows.
    pub(in crate::integrator) fn forget(&mut self) {
        self.valid = false;
        self.point_tri = Vec::new();
        self.edge_edge = Vec::new();
    }

    /// Keeps `point_tri` and `edge_edge`, measured now, as every pair within `built`.
    pub(in crate::integrator) fn rebuild(
        &mut self,
        built: f64,
        point_tri: Vec<Part>,
        edge_edge: Vec<Part>,
    ) {
        self.built = built;
        self.valid = true;
        self.travel.clear();
        self.travel.resize(self.last.len(), 0.0);
        self.most = 0.0;
        self.point_tri = point_tri;
        self.edge_edge = edge_edge;
    }

    /// The pairs within `reach` at `x`, in the list's order: `(point, triangle, distance)`
    /// and `(edge, earlier edge, distance)`. A pair whose budget shows it beyond the reach
    /// is not measured; every other is, and its distance and travel kept.
    #[allow(clippy::type_complexity)]
    pub(in crate::integrator) fn within(
        &mut self,
        topo: &Topology,
        x: &[Vec3],
        reach: f64,
    ) -> (Vec<(u32, u32, f64)>, Vec<(u32, u32, f64)>) {
        let travel = &self.travel;
        let points = check(
            &mut self.point_tri,
            reach,
            |a, b| {
                let (tri, _) = topo.triangles[b as usize];
                travel[a as usize] + tri.iter().map(|&i| travel[i as usize]).sum::<f64>()
            },
            |a, b| {
                let (tri, _) = topo.triangles[b as usize];
                point_triangle_distance(&x[a as usize], tri.map(|i| &x[i as usize]))
            },
        );
        let ends = |e: u32, f: u32| {
            let ([a, b], _) = topo.edges[e as usize];
            let ([c, d], _) = topo.edges[f as usize];
            [a, b, c, d]
        };
        let edges = check(
            &mut self.edge_edge,
            reach,
            |e, f| ends(e, f).iter().map(|&i| travel[i as usize]).sum::<f64>(),
            |e, f| segment_distance(ends(e, f).map(|i| &x[i as usize])),
        );
        (points, edges)
    }
}

/// Checks the listed pairs `(a, b)`, a part at a time in parallel: each whose budget (its
/// particles' travel summed now, `travel`) does not keep it beyond `reach` is measured
/// (`measure`), and returned when within it. Results in list order.
fn check(
    list: &mut [Part],
    reach: f64,
    travel: impl Fn(u32, u32) -> f64 + Sync,
    measure: impl Fn(u32, u32) -> f64 + Sync,
) -> Vec<(u32, u32, f64)> {
    let run = |part: &mut Part| {
        let mut out = Vec::new();
        let mut begin = 0;
        for &(a, end) in &part.runs {
            for c in &mut part.pairs[begin as usize..end as usize] {
                let t = travel(a, c.b);
                let bound = f64::from(c.bound);
                // The distance less the travel since its test, by the triangle inequality.
                if bound - t >= reach + ROUNDING * bound {
                    continue;
                }
                let distance = measure(a, c.b);
                c.bound = down(distance + t);
                if distance < reach {
                    out.push((a, c.b, distance));
                }
            }
            begin = end;
        }
        out
    };
    if list.len() == 1 {
        return run(&mut list[0]);
    }
    concatenate(list.par_iter_mut().map(run).collect())
}

/// Every point–triangle pair (a surface particle, a triangle not holding it) and edge–edge
/// pair (sharing no particle; each unordered pair once) of the surfaces within `reach` at
/// `x` that `skip` does not hold apart, measured, through the grids' search. Each search's
/// grid and boxes go before the next is made: with the list being built, they were a
/// build's peak memory.
pub(in crate::integrator) fn search(
    (topo, skip): (&Topology, &Exclusion),
    x: &[Vec3],
    reach: f64,
) -> (Vec<Part>, Vec<Part>) {
    let point_tri = point_triangle_pairs((topo, skip), x, reach);
    (point_tri, edge_pairs((topo, skip), x, reach))
}

/// The point–triangle pairs of [`search`].
fn point_triangle_pairs(
    (topo, skip): (&Topology, &Exclusion),
    x: &[Vec3],
    reach: f64,
) -> Vec<Part> {
    let mut triangle_grid = Grid::default();
    let tri_boxes: Vec<(Vec3, Vec3)> = topo
        .triangles
        .iter()
        .map(|(t, _)| bounds_of(&t.map(|i| &x[i as usize]).each_ref().map(|p| *p)))
        .collect();
    bin(&mut triangle_grid, &tri_boxes, reach);
    let grid = &triangle_grid;
    let at: Vec<Cell> = x.iter().map(|p| grid.cell_of(p)).collect();
    let point = |v: usize| (x[v], x[v]);
    by_cell(
        grid,
        &at,
        (&point, &tri_boxes, reach),
        |v, candidates, skipped, out: &mut Part| {
            if topo.surface[v] == u16::MAX {
                return;
            }
            let p = &x[v];
            skipped.hold(skip.triangles_of(v as u32), |skipped| {
                for &t in candidates {
                    let (tri, _) = topo.triangles[t as usize];
                    if tri.contains(&(v as u32))
                        || !within(p, &tri_boxes[t as usize], reach)
                        || skipped[t as usize]
                    {
                        continue;
                    }
                    let d = point_triangle_distance(p, tri.map(|i| &x[i as usize]));
                    if d < reach {
                        out.push(v as u32, t, d);
                    }
                }
            });
        },
        Part::shrink,
    )
}

/// The edge–edge pairs of [`search`].
fn edge_pairs((topo, skip): (&Topology, &Exclusion), x: &[Vec3], reach: f64) -> Vec<Part> {
    let mut edge_grid = Grid::default();
    let edge_boxes: Vec<(Vec3, Vec3)> = topo
        .edges
        .iter()
        .map(|([a, b], _)| {
            (
                x[*a as usize].inf(&x[*b as usize]),
                x[*a as usize].sup(&x[*b as usize]),
            )
        })
        .collect();
    bin(&mut edge_grid, &edge_boxes, reach);
    let grid = &edge_grid;
    let at: Vec<Cell> = edge_boxes.iter().map(|(lo, _)| grid.cell_of(lo)).collect();
    let edge = |e: usize| edge_boxes[e];
    by_cell(
        grid,
        &at,
        (&edge, &edge_boxes, reach),
        |e, candidates, skipped, out: &mut Part| {
            let ([a, b], _) = topo.edges[e];
            let bx = &edge_boxes[e];
            skipped.hold(skip.edges_below(e as u32), |skipped| {
                for &f in candidates {
                    let f = f as usize;
                    if f >= e {
                        continue;
                    }
                    let ([c0, d0], _) = topo.edges[f];
                    if [c0, d0].contains(&a)
                        || [c0, d0].contains(&b)
                        || !boxes_within(bx, &edge_boxes[f], reach)
                        || skipped[f]
                    {
                        continue;
                    }
                    let d = segment_distance([a, b, c0, d0].map(|i| &x[i as usize]));
                    if d < reach {
                        out.push(e as u32, f as u32, d);
                    }
                }
            });
        },
        Part::shrink,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::model::surface::Surface;

    /// A 14×14 sheet folded over itself, each point nudged by a fixed pseudo-random amount:
    /// pairs at every distance, above and beside each other.
    fn folded_sheet() -> (Model, Vec<Vec3>) {
        let (n, s) = (14usize, 0.01);
        let mut state = 12345u64;
        let mut jitter = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.4 * s
        };
        let mut x = Vec::new();
        for j in 0..n {
            for i in 0..n {
                // The far half turned back over the near half, 0.6 spacings above it.
                let (z, y) = if j < n / 2 {
                    (j as f64 * s, 0.0)
                } else {
                    ((n - 1 - j) as f64 * s, 0.6 * s)
                };
                x.push(Vec3::new(
                    i as f64 * s + jitter(),
                    y + jitter(),
                    z + jitter(),
                ));
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u32;
                let (b, c, d) = (a + 1, a + n as u32, a + n as u32 + 1);
                triangles.push([a, b, d]);
                triangles.push([a, d, c]);
            }
        }
        let model = Model {
            surfaces: vec![Surface {
                particles: 0..n * n,
                triangles,
                thickness: 0.002,
                self_collision: true,
                friction: 0.0,
            }],
            ..Model::default()
        };
        (model, x)
    }

    /// The search finds every point–triangle and edge–edge pair within the reach, with the
    /// distance measuring it alone gives, and nothing else: what the list's budgets and
    /// each cell's pruning rest on.
    #[test]
    fn the_search_finds_exactly_the_pairs_a_test_of_every_pair_finds() {
        let (model, x) = folded_sheet();
        let topo = Topology::new(&model, x.len());
        let reach = 0.013;
        let (point_tri, edge_edge) = search((&topo, &Exclusion::default()), &x, reach);
        let mut want_points = Vec::new();
        for v in 0..x.len() {
            for (t, (tri, _)) in topo.triangles.iter().enumerate() {
                if tri.contains(&(v as u32)) {
                    continue;
                }
                let d = point_triangle_distance(&x[v], tri.map(|i| &x[i as usize]));
                if d < reach {
                    want_points.push((v as u32, t as u32, down(d).to_bits()));
                }
            }
        }
        let mut want_edges = Vec::new();
        for (e, ([a, b], _)) in topo.edges.iter().enumerate() {
            for (f, ([c, d], _)) in topo.edges.iter().enumerate().take(e) {
                if [c, d].contains(&a) || [c, d].contains(&b) {
                    continue;
                }
                let dist = segment_distance([a, b, c, d].map(|&i| &x[i as usize]));
                if dist < reach {
                    want_edges.push((e as u32, f as u32, down(dist).to_bits()));
                }
            }
        }
        let found = |list: &[Part]| {
            let mut v: Vec<_> = list
                .iter()
                .flat_map(Part::iter)
                .map(|(a, b, bound)| (a, b, bound.to_bits()))
                .collect();
            v.sort_unstable();
            v
        };
        want_points.sort_unstable();
        want_edges.sort_unstable();
        // The fold puts pairs across the layers within the reach, not only neighbours.
        assert!(want_points.len() > 1000 && want_edges.len() > 1000);
        assert_eq!(found(&point_tri), want_points);
        assert_eq!(found(&edge_edge), want_edges);
    }

    /// A bound rounded to single precision is never above the double it stands for, and
    /// within one unit in the last place below it.
    #[test]
    fn a_bound_is_rounded_down() {
        for x in [0.0, 1e-9, 0.0094, 0.1 + 0.2, 1.0 / 3.0, 7.3e-3, 1e30, 1e300] {
            let f = down(x);
            assert!(f64::from(f) <= x, "{x}");
            assert!(f64::from(f.next_up()) > x, "{x}");
        }
        assert_eq!(down(0.5), 0.5);
        assert_eq!(down(f64::INFINITY), f32::INFINITY);
        assert!(down(f64::NAN).is_nan());
    }
}
