//! Detection for block descent: the contacts each particle's local solve feels, and the
//! displacement bound that keeps every surface from crossing a collider or another surface
//! until the next detection (the offset-bound idea of Chen et al. 2025, written for this
//! model's colliders and surfaces; docs/physics.md §4.1).
//!
//! Each particle `v` moves, between two detections, within a ball of radius `b_v` around
//! `x_v + u` (positions at the detection; `u` a translation shared by every surface
//! particle, zero for the rest). With `d` the distance of two primitives at the detection:
//!
//! * a point and a non-incident triangle, or two edges sharing no particle, of the surfaces:
//!   both sides share `u`, so the gap changes by at most the two sides' `b`; every `b` of
//!   either side is at most `γ_s d`, and `2 γ_s < 1` keeps the gap open;
//! * a particle or a surface triangle and a collider (which does not move): the point moves
//!   at most `|u| + b ≤ γ_c d` with `γ_c < 1`.
//!
//! Distances are searched only up to a reach (`R_s`, `R_c`); a pair farther than the reach
//! bounds by the reach, which is enough for the same argument. The bound holds whatever the
//! step size: the integrator can fail to converge, never cross.

use super::candidates::{Candidates, SKIN, search};
use super::graph::Graph;
use super::pairs::{Pair, Sides, stencil_distance};
use super::planes::{HalfSpaces, Plane, Touches};
use crate::collider::response::Response;
use crate::contact::grid::{Cell, Grid};
use crate::contact::proximity::feature_triangle;
use crate::model::Model;
use crate::particles::{Particles, Vec3};
use rayon::prelude::*;
use std::ops::Range;

/// Share of a surface-to-surface distance each side may use up: below one half.
pub(crate) const GAMMA_SURFACE: f64 = 0.4;
/// Share of a distance to a collider a particle may use up: below one.
pub(crate) const GAMMA_COLLIDER: f64 = 0.9;
/// Reach of the search between surfaces, in thicknesses.
const SURFACE_REACH: f64 = 4.0;
/// Least reach of the search for colliders, in thicknesses.
const COLLIDER_REACH: f64 = 10.0;
/// Pairs nearer than this many thicknesses are felt until the next detection; farther ones
/// bound the motion instead, so that they cannot come within a thickness unfelt.
const FELT: f64 = 2.0;
/// Contact stiffness as a multiple of a particle's own stiffness scale `m/dt² + Σ ks`.
pub(crate) const CONTACT_STIFFNESS: f64 = 1.0;
/// Particles (or triangles, edges) per parallel chunk of the detection.
const CHUNK: usize = 512;

/// How near a primitive's nearest neighbour is, and its nearest neighbour whose contact is
/// not felt (farther than [`FELT`] thicknesses), capped at the search's reach.
#[derive(Clone, Copy, Debug)]
struct Clearance {
    nearest: f64,
    unfelt: f64,
}

impl Clearance {
    fn new(reach: f64) -> Self {
        Self {
            nearest: reach,
            unfelt: reach,
        }
    }

    fn see(&mut self, d: f64, felt: bool) {
        self.nearest = self.nearest.min(d);
        if !felt {
            self.unfelt = self.unfelt.min(d);
        }
    }

    fn meet(&mut self, other: &Clearance) {
        self.nearest = self.nearest.min(other.nearest);
        self.unfelt = self.unfelt.min(other.unfelt);
    }

    /// The motion this clearance allows one side of its pairs: `gamma` of the nearest
    /// distance, and no nearer than `h` to the unfelt ones, whose other side moves as much
    /// (`sides` = 2) or not at all (`sides` = 1, a collider).
    fn allows(&self, gamma: f64, h: f64, sides: f64) -> f64 {
        (gamma * self.nearest).min((self.unfelt - h) / sides)
    }
}

/// The surfaces' primitives, fixed for a model.
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Topology {
    built_for: usize,
    /// Active surfaces' triangles and edges, with their surface's index.
    pub(in crate::integrator) triangles: Vec<([u32; 3], u16)>,
    pub(in crate::integrator) edges: Vec<([u32; 2], u16)>,
    /// Per particle: its active surface, or `u16::MAX`.
    pub(in crate::integrator) surface: Vec<u16>,
    /// Whether any surface pair (self or between bodies) can touch.
    self_pairs: bool,
    /// The thickness particles outside every active surface keep from velocity-level
    /// colliders ([`Model::point_thickness`]).
    point: f64,
    /// Per triangle: which of its edges (bits 0..3: ab, bc, ca) and corners (bits 3..6)
    /// it owns, being the first triangle of its surface to have them.
    owns: Vec<u8>,
}

impl Topology {
    /// The thickness particle `i` keeps: its active surface's, zero outside every one.
    fn margin(&self, model: &Model, i: usize) -> f64 {
        match self.surface[i] {
            u16::MAX => 0.0,
            s => model.surfaces[s as usize].thickness,
        }
    }

    /// The thickness particle `i` keeps from the colliders that bound it (velocity-level
    /// ones): its surface's, or the point thickness outside every active surface.
    fn contact_margin(&self, model: &Model, i: usize) -> f64 {
        match self.surface[i] {
            u16::MAX => self.point,
            s => model.surfaces[s as usize].thickness,
        }
    }

    /// The thickness particle `i` keeps from a collider answering with `response`: its
    /// surface's from a penalty wall (the course's force field, which it may enter), and
    /// at least the point thickness from the others.
    fn keeps(&self, model: &Model, i: usize, response: &Response) -> f64 {
        match response {
            Response::Penalty { .. } => self.margin(model, i),
            _ => self.contact_margin(model, i),
        }
    }

    fn new(model: &Model, n: usize) -> Self {
        let mut t = Self {
            built_for: n,
            surface: vec![u16::MAX; n],
            point: model.point_thickness(),
            ..Self::default()
        };
        let active: Vec<_> = model.active_surfaces().collect();
        for &(k, s) in &active {
            for p in s.particles.clone() {
                t.surface[p] = k as u16;
            }
            t.triangles
                .extend(s.triangles.iter().map(|&tri| (tri, k as u16)));
            t.edges.extend(s.edges().into_iter().map(|e| (e, k as u16)));
        }
        t.self_pairs = active.len() > 1 || active.iter().any(|(_, s)| s.self_collision);
        let mut edges = std::collections::HashSet::new();
        let mut corners = vec![false; n];
        t.owns = t
            .triangles
            .iter()
            .map(|([a, b, c], _)| {
                let mut mask = 0u8;
                for (k, (u, v)) in [(a, b), (b, c), (c, a)].into_iter().enumerate() {
                    if edges.insert((*u.min(v), *u.max(v))) {
                        mask |= 1 << k;
                    }
                }
                for (k, v) in [a, b, c].into_iter().enumerate() {
                    if !std::mem::replace(&mut corners[*v as usize], true) {
                        mask |= 1 << (3 + k);
                    }
                }
                mask
            })
            .collect();
        t
    }
}

/// The result of a detection, and its buffers.
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Detection {
    topology: Topology,
    triangle_grid: Grid,
    edge_grid: Grid,
    /// Positions at the first step: pairs nearer than their gap there are neighbours in the
    /// body's own rest shape, not contacts.
    rest: Vec<Vec3>,
    /// Per particle: the collider surfaces it may reach before the next detection, each as
    /// its tangent plane at the detection.
    pub(in crate::integrator) touches: Vec<Touches>,
    /// Per particle: the half-space colliders near it, which bound only the motion that
    /// closes its gap to them.
    pub(in crate::integrator) halves: Vec<HalfSpaces>,
    /// Surface pairs and feature pairs within reach.
    pub(in crate::integrator) pairs: Vec<Pair>,
    /// Per free body of the graph: whether a surface pair joins it to another body (then
    /// it is left out of the coarse correction, docs/physics.md §4.1).
    pub(in crate::integrator) touches_another: Vec<bool>,
    /// Particle `i`'s pairs are `refs[start[i]..start[i + 1]]`.
    start: Vec<u32>,
    refs: Vec<u32>,
    /// The counting sort's write positions.
    cursor: Vec<u32>,
    /// Per particle: the centre offset (`u` or zero) and radius of the ball it stays in.
    pub(in crate::integrator) shift: Vec3,
    pub(in crate::integrator) shifted: Vec<bool>,
    pub(in crate::integrator) bound: Vec<f64>,
    /// Per particle, per triangle, per edge: distances found (capped at the reach).
    point_collider: Vec<Clearance>,
    triangle_collider: Vec<Clearance>,
    point_surface: Vec<Clearance>,
    triangle_surface: Vec<Clearance>,
    edge_surface: Vec<Clearance>,
    /// Buffers of the bounds, kept so that a detection allocates nothing on a model
    /// without surface pairs.
    scratch_collider: Vec<Clearance>,
    scratch_own: Vec<Clearance>,
    scratch_allowed: Vec<f64>,
    /// Surface pairs kept between detections (see [`Candidates`]).
    candidates: Candidates,
    /// The largest thickness of the active surfaces.
    h_max: f64,
    /// Per particle: how far a pinned surface particle moves over the step apart from the
    /// shared translation, `|c - u|` (`c` its keyed displacement); zero for the rest.
    excess: Vec<f64>,
    /// Per particle: its stiffness scale `m/dt² + Σ ks`.
    pub(in crate::integrator) scale: Vec<f64>,
}

/// `f` over fixed chunks of `0..n` in parallel, results concatenated in chunk order.
fn chunked<T: Send>(n: usize, f: impl Fn(Range<usize>) -> Vec<T> + Sync + Send) -> Vec<T> {
    if n <= CHUNK {
        return f(0..n);
    }
    let parts: Vec<Vec<T>> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| f(c * CHUNK..((c + 1) * CHUNK).min(n)))
        .collect();
    parts.into_iter().flatten().collect()
}

/// The box holding `points` (at least one).
pub(in crate::integrator) fn bounds_of(points: &[&Vec3]) -> (Vec3, Vec3) {
    let mut lo = *points[0];
    let mut hi = *points[0];
    for p in &points[1..] {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

/// Whether point `p` lies in box `lo..hi` grown by `r`.
pub(in crate::integrator) fn within(p: &Vec3, (lo, hi): &(Vec3, Vec3), r: f64) -> bool {
    (0..3).all(|k| p[k] >= lo[k] - r && p[k] <= hi[k] + r)
}

/// Whether boxes `a` and `b` come within `r` of each other.
pub(in crate::integrator) fn boxes_within(a: &(Vec3, Vec3), b: &(Vec3, Vec3), r: f64) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] + r && b.0[k] <= a.1[k] + r)
}

/// Bins `boxes` into `grid` with cells as large as the largest box plus `reach`, so that
/// everything within `reach` of a query lies in the 27 cells around it ([`by_cell`]).
pub(in crate::integrator) fn bin(grid: &mut Grid, boxes: &[(Vec3, Vec3)], reach: f64) {
    let extent = boxes
        .iter()
        .map(|(lo, hi)| (hi - lo).max())
        .fold(0.0, f64::max);
    grid.build(extent + reach, boxes.iter().map(|(lo, _)| *lo));
}

/// Calls `test(q, candidates, out)` for every query `q` whose cell is `cells[q]`, with the
/// items of the 27 cells around that cell (every item whose low corner lies within one cell
/// of the query's), gathered once per occupied cell. Results come in the order of (cell,
/// query): fixed by the positions alone, never by threads.
pub(in crate::integrator) fn by_cell<T: Send>(
    grid: &Grid,
    cells: &[Cell],
    test: impl Fn(usize, &[u32], &mut Vec<T>) + Sync + Send,
) -> Vec<T> {
    let mut order: Vec<u32> = (0..cells.len() as u32).collect();
    order.sort_unstable_by_key(|&q| (cells[q as usize], q));
    let mut starts: Vec<usize> = (0..order.len())
        .filter(|&k| k == 0 || cells[order[k] as usize] != cells[order[k - 1] as usize])
        .collect();
    starts.push(order.len());
    chunked(starts.len() - 1, |groups| {
        let mut out = Vec::new();
        let mut candidates = Vec::new();
        for g in groups {
            let members = &order[starts[g]..starts[g + 1]];
            let c = cells[members[0] as usize];
            candidates.clear();
            for i in -1..=1 {
                for j in -1..=1 {
                    for k in -1..=1 {
                        grid.visit([c[0] + i, c[1] + j, c[2] + k], |t| candidates.push(t));
                    }
                }
            }
            for &q in members {
                test(q as usize, &candidates, &mut out);
            }
        }
        out
    })
}

/// The normal stiffness and Coulomb coefficient a collider's response gives a contact with
/// stiffness scale `scale`.
pub(in crate::integrator) fn collider_law(response: &Response, scale: f64) -> (f64, f64) {
    match *response {
        Response::Penalty { kc, .. } => (kc, 0.0),
        Response::Restitution { friction, .. } => (CONTACT_STIFFNESS * scale, friction),
        Response::Stick => (CONTACT_STIFFNESS * scale, f64::INFINITY),
    }
}

impl Detection {
    /// Particle `i`'s pairs.
    #[inline]
    pub(in crate::integrator) fn pairs_of(&self, i: usize) -> impl Iterator<Item = &Pair> {
        self.refs[self.start[i] as usize..self.start[i + 1] as usize]
            .iter()
            .map(|&k| &self.pairs[k as usize])
    }

    /// The indices into [`Detection::pairs`] of particle `i`'s pairs.
    #[inline]
    pub(in crate::integrator) fn pair_indices(&self, i: usize) -> &[u32] {
        &self.refs[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Marks the graph's free bodies that a surface pair joins to another body: corrected
    /// alone, each would push the other back and forth (a stack jitters).
    fn mark_touching_bodies(&mut self, graph: &Graph) {
        self.touches_another.clear();
        self.touches_another.resize(graph.free_bodies.len(), false);
        for pair in &self.pairs {
            // A feature pair's other side is a collider, not a body.
            if matches!(pair.sides, Sides::Feature(..)) {
                continue;
            }
            let bodies = pair
                .ids
                .iter()
                .filter(|&&j| j != u32::MAX)
                .map(|&j| graph.body_of[j as usize]);
            let mut others = bodies.clone();
            let Some(first) = others.next() else {
                continue;
            };
            if others.all(|b| b == first) {
                continue;
            }
            // Bodies with no free index (pinned ones) have nothing to mark.
            for b in bodies {
                if let Some(t) = self.touches_another.get_mut(b as usize) {
                    *t = true;
                }
            }
        }
    }

    /// Whether any pair was found.
    pub(in crate::integrator) fn has_pairs(&self) -> bool {
        !self.pairs.is_empty()
    }

    /// Calls `f` with every particle that shares a pair with particle `i`.
    pub(in crate::integrator) fn partners(&self, i: usize, f: &mut dyn FnMut(u32)) {
        for pair in self.pairs_of(i) {
            for &j in &pair.ids {
                if j != u32::MAX && j as usize != i {
                    f(j);
                }
            }
        }
    }

    /// Whether particle `i` may feel a contact before the next detection.
    #[inline]
    pub(in crate::integrator) fn may_touch(&self, i: usize) -> bool {
        self.touches[i].count != 0 || self.start[i] != self.start[i + 1]
    }

    /// The thickness particle `i` keeps from penalty colliders: its surface's.
    #[inline]
    pub(in crate::integrator) fn margin(&self, model: &Model, i: usize) -> f64 {
        self.topology.margin(model, i)
    }

    /// The thickness particle `i` keeps from a collider answering with `response`: a point
    /// keeps [`Model::point_thickness`] from velocity-level colliders.
    #[inline]
    pub(in crate::integrator) fn keeps(&self, model: &Model, i: usize, response: &Response) -> f64 {
        self.topology.keeps(model, i, response)
    }

    /// Detects at positions `x` (the current iterate), with `y` the step's inertial targets
    /// (which set how far the search reaches and the shared translation `u`).
    pub(in crate::integrator) fn detect(
        &mut self,
        model: &Model,
        p: &Particles,
        graph: &Graph,
        (x, y): (&[Vec3], &[Vec3]),
        dt: f64,
    ) {
        let n = x.len();
        if self.topology.built_for != n || self.rest.len() != n {
            self.topology = Topology::new(model, n);
            self.rest = x.to_vec();
        }
        self.scale.clear();
        self.scale
            .extend((0..n).map(|i| p.mass[i] / (dt * dt) + graph.stiffness[i]));
        let h_max = model
            .active_surfaces()
            .map(|(_, s)| s.thickness)
            .fold(0.0, f64::max);
        self.h_max = h_max;
        let points = self.topology.surface.contains(&u16::MAX);
        let h_collider = if points {
            h_max.max(self.topology.point)
        } else {
            h_max
        };
        let travel = (0..n)
            .filter(|&i| !p.is_pinned(i))
            .map(|i| (y[i] - x[i]).norm())
            .fold(0.0, f64::max);
        // Without colliders nothing bounds a particle but the surfaces.
        let collider_reach = if model.colliders.is_empty() {
            f64::INFINITY
        } else {
            (COLLIDER_REACH * h_collider).max(4.0 * travel).max(1e-6)
        };
        self.detect_colliders(model, x, collider_reach);
        self.detect_features(model, x, collider_reach, dt);
        let allowed = self.collider_allowance(model);
        self.set_shift(p, (x, y), &allowed);
        // Surfaces are searched far enough that pairs beyond the reach stay apart however
        // far keyed pins move from the shared translation (see `set_radii`).
        let pins = self.excess.iter().fold(0.0, |a: f64, &b| a.max(b));
        let surface_reach = (SURFACE_REACH * h_max).max(4.0 * pins);
        self.detect_surfaces(model, x, surface_reach);
        self.index_pairs(n, p);
        self.mark_touching_bodies(graph);
        self.set_radii(allowed, surface_reach);
    }

    /// Per particle: the nearest collider surface (capped at `reach`) and which colliders
    /// it may touch before the next detection.
    fn detect_colliders(&mut self, model: &Model, x: &[Vec3], reach: f64) {
        let topology = &self.topology;
        let n = x.len();
        self.point_collider.resize(n, Clearance::new(reach));
        self.touches.resize(n, Touches::default());
        self.halves.resize(n, HalfSpaces::default());
        let one = |i: usize, (clearance, near, halves): (&mut Clearance, &mut Touches, &mut HalfSpaces)| {
            let (lo, hi) = (x[i].add_scalar(-reach), x[i].add_scalar(reach));
            *clearance = Clearance::new(reach);
            *near = Touches::default();
            *halves = HalfSpaces::default();
            for (k, slot) in model.colliders.iter().enumerate() {
                if !slot.shape.may_touch(&lo, &hi, 0.0) {
                    continue;
                }
                let half = slot.shape.is_half_space();
                // A penalty collider is a force field the course lets particles enter: it
                // bounds nothing, and its surface is felt wherever the search reaches.
                let force = slot.response.is_force();
                let margin = topology.keeps(model, i, &slot.response);
                slot.shape.contacts_within(&x[i], reach, &mut |c| {
                    let d = reach - c.depth;
                    // Inside already: no bound from it (staying is no crossing); its
                    // contact pushes the particle out.
                    let inside = d < 0.0;
                    let felt = force || inside || d <= FELT * margin;
                    // A half-space bounds only the motion along its normal.
                    let kept = half && !force && !inside && halves.keep(c.point, c.normal, d);
                    if !force && !inside && !kept {
                        clearance.see(d, felt);
                    }
                    if felt {
                        let plane = Plane {
                            collider: k as u16,
                            point: c.point,
                            normal: c.normal,
                        };
                        near.keep(plane, d);
                    }
                });
            }
        };
        let (clearances, near, halves) = (
            &mut self.point_collider,
            &mut self.touches,
            &mut self.halves,
        );
        if n <= CHUNK {
            for i in 0..n {
                one(i, (&mut clearances[i], &mut near[i], &mut halves[i]));
            }
        } else {
            clearances
                .par_chunks_mut(CHUNK)
                .zip(near.par_chunks_mut(CHUNK))
                .zip(halves.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(|(c, ((cl, ne), ha))| {
                    for k in 0..cl.len() {
                        one(c * CHUNK + k, (&mut cl[k], &mut ne[k], &mut ha[k]));
                    }
                });
        }
    }

    /// Per surface triangle: the nearest sharp collider feature (capped at `reach`), and the
    /// feature pairs it may touch before the next detection, with how far each feature
    /// point moves in the step of length `dt`.
    fn detect_features(&mut self, model: &Model, x: &[Vec3], reach: f64, dt: f64) {
        let triangles = &self.topology.triangles;
        self.triangle_collider.clear();
        self.triangle_collider
            .resize(triangles.len(), Clearance::new(reach));
        self.pairs.clear();
        if !model.colliders.iter().any(|c| c.shape.has_features()) {
            return;
        }
        let scale = &self.scale;
        let (points, touches) = (&self.point_collider, &self.touches);
        let found = chunked(triangles.len(), |range| {
            let mut out = Vec::new();
            for t in range {
                let (tri, s) = triangles[t];
                let [a, b, c] = tri.map(|i| &x[i as usize]);
                let (lo, hi) = bounds_of(&[a, b, c]);
                let h = model.surfaces[s as usize].thickness;
                let mut clearance = Clearance::new(reach);
                // A feature is a point of a collider's surface, so it is at least as far
                // from a corner as the nearest surface point is, and at least that less the
                // triangle's size from the triangle: a triangle whose corners all see no
                // surface within the reach plus its size has no feature within the reach
                // (unless a corner is inside something, which its contacts then say).
                let nearest = tri
                    .iter()
                    .map(|&i| points[i as usize].nearest)
                    .fold(0.0, f64::max);
                let size = (a - b).norm().max((b - c).norm()).max((c - a).norm());
                let felt = tri.iter().any(|&i| touches[i as usize].count != 0);
                if !felt && nearest - size >= reach {
                    out.push((t, clearance, Vec::new()));
                    continue;
                }
                let mut pairs = Vec::new();
                for slot in model.colliders.iter().filter(|c| c.shape.has_features()) {
                    let (k, mu) = collider_law(
                        &slot.response,
                        tri.iter().map(|&i| scale[i as usize]).fold(0.0, f64::max),
                    );
                    slot.shape
                        .features(&lo.add_scalar(-reach), &hi.add_scalar(reach), &mut |f| {
                            // The boxes' distance bounds the feature's from below: a feature
                            // no nearer than what is already known, and not felt, changes
                            // nothing.
                            let (flo, fhi) = f.bounds();
                            let apart = (0..3)
                                .map(|k| (flo[k] - hi[k]).max(lo[k] - fhi[k]).max(0.0).powi(2))
                                .sum::<f64>()
                                .sqrt();
                            if apart >= clearance.nearest && apart > FELT * h {
                                return;
                            }
                            let (anchor, w) = feature_triangle(&f, a, b, c);
                            let d = (a * w[0] + b * w[1] + c * w[2] - anchor).norm();
                            clearance.see(d, d <= FELT * h);
                            if d <= FELT * h {
                                let carry = slot.shape.velocity(&anchor) * dt;
                                pairs.push(Pair {
                                    sides: Sides::Feature(anchor, carry),
                                    ids: [tri[0], tri[1], tri[2], u32::MAX],
                                    h,
                                    k,
                                    mu,
                                });
                            }
                        });
                }
                out.push((t, clearance, pairs));
            }
            out
        });
        for (t, d, pairs) in found {
            self.triangle_collider[t] = d;
            self.pairs.extend(pairs);
        }
    }

    /// Point–triangle and edge–edge distances between surfaces (capped at `reach`), and the
    /// pairs within reach.
    fn detect_surfaces(&mut self, model: &Model, x: &[Vec3], reach: f64) {
        let n = x.len();
        let topo = &self.topology;
        self.point_surface.clear();
        self.point_surface.resize(n, Clearance::new(reach));
        self.triangle_surface.clear();
        self.triangle_surface
            .resize(topo.triangles.len(), Clearance::new(reach));
        self.edge_surface.clear();
        self.edge_surface
            .resize(topo.edges.len(), Clearance::new(reach));
        if !topo.self_pairs || reach <= 0.0 {
            return;
        }
        let surfaces = &model.surfaces;
        let law = |a: u16, b: u16| -> Option<(f64, f64)> {
            let (sa, sb) = (&surfaces[a as usize], &surfaces[b as usize]);
            if a == b && !sa.self_collision {
                return None;
            }
            Some((
                sa.thickness.max(sb.thickness),
                0.5 * (sa.friction + sb.friction),
            ))
        };
        let scale = &self.scale;
        let stiffness = |ids: &[u32]| {
            CONTACT_STIFFNESS * ids.iter().map(|&i| scale[i as usize]).fold(0.0, f64::max)
        };
        let rest = &self.rest;
        self.candidates.update(topo, x, reach);
        if self.candidates.stale(reach) {
            let built = reach + SKIN * reach;
            let (point_tri, edge_edge) = search(
                topo,
                x,
                built,
                (&mut self.triangle_grid, &mut self.edge_grid),
            );
            self.candidates.rebuild(built, point_tri, edge_edge);
        }
        let (found, found_edges) = self.candidates.within(topo, x, reach);
        let found: Vec<_> = found
            .into_iter()
            .filter_map(|(v, t, d)| {
                let law = law(topo.surface[v as usize], topo.triangles[t as usize].1)?;
                Some((v as usize, t, d, law.0, law.1))
            })
            .collect();
        for (v, t, d, h, mu) in found {
            let tri = topo.triangles[t as usize].0;
            let felt = d <= FELT * h;
            // The pair's distance less what its keyed pins move apart from the shared
            // translation: the room its free particles share (see `set_radii`).
            let pins = tri
                .iter()
                .map(|&i| self.excess[i as usize])
                .fold(0.0, f64::max);
            let r = d - self.excess[v] - pins;
            self.point_surface[v].see(r, felt);
            self.triangle_surface[t as usize].see(r, felt);
            if !felt {
                continue;
            }
            let ids = [v as u32, tri[0], tri[1], tri[2]];
            let pair = Pair {
                sides: Sides::PointTriangle(topo.owns[t as usize]),
                ids,
                h,
                k: stiffness(&ids),
                mu,
            };
            if stencil_distance(&pair, rest) >= h {
                self.pairs.push(pair);
            }
        }

        let found: Vec<_> = found_edges
            .into_iter()
            .filter_map(|(e, f, d)| {
                let law = law(topo.edges[e as usize].1, topo.edges[f as usize].1)?;
                Some((e as usize, f as usize, d, law.0, law.1))
            })
            .collect();
        for (e, f, d, h, mu) in found {
            let felt = d <= FELT * h;
            let ([a, b], _) = topo.edges[e];
            let ([c, dd], _) = topo.edges[f];
            let most = |i: u32, j: u32| self.excess[i as usize].max(self.excess[j as usize]);
            let r = d - most(a, b) - most(c, dd);
            self.edge_surface[e].see(r, felt);
            self.edge_surface[f].see(r, felt);
            if !felt {
                continue;
            }
            let ([a, b], _) = topo.edges[e];
            let ([c, dd], _) = topo.edges[f];
            let ids = [a, b, c, dd];
            let pair = Pair {
                sides: Sides::EdgeEdge,
                ids,
                h,
                k: stiffness(&ids),
                mu,
            };
            if stencil_distance(&pair, rest) >= h {
                self.pairs.push(pair);
            }
        }
    }

    /// Lists each particle's pairs (a counting sort in pair order).
    fn index_pairs(&mut self, n: usize, p: &Particles) {
        self.start.clear();
        self.start.resize(n + 1, 0);
        let free = |i: u32| i != u32::MAX && !p.is_pinned(i as usize);
        for pair in &self.pairs {
            for &i in pair.ids.iter().filter(|&&i| free(i)) {
                self.start[i as usize + 1] += 1;
            }
        }
        for i in 0..n {
            self.start[i + 1] += self.start[i];
        }
        self.refs.clear();
        self.refs.resize(self.start[n] as usize, 0);
        let cursor = &mut self.cursor;
        cursor.clear();
        cursor.extend_from_slice(&self.start);
        for (k, pair) in self.pairs.iter().enumerate() {
            for &i in pair.ids.iter().filter(|&&i| free(i)) {
                self.refs[cursor[i as usize] as usize] = k as u32;
                cursor[i as usize] += 1;
            }
        }
    }

    /// Per particle: how far its collider clearance (its triangles' features included) lets
    /// it move, `γ_c` of the nearest distance and no nearer than its thickness to the
    /// unfelt ones.
    fn collider_allowance(&mut self, model: &Model) -> Vec<f64> {
        let topo = &self.topology;
        let mut collider = std::mem::take(&mut self.scratch_collider);
        collider.clear();
        collider.extend_from_slice(&self.point_collider);
        for (t, (tri, _)) in topo.triangles.iter().enumerate() {
            for &i in tri {
                collider[i as usize].meet(&self.triangle_collider[t]);
            }
        }
        let mut allowed = std::mem::take(&mut self.scratch_allowed);
        allowed.clear();
        allowed.extend(
            (0..collider.len())
                .map(|i| collider[i].allows(GAMMA_COLLIDER, topo.contact_margin(model, i), 1.0)),
        );
        self.scratch_collider = collider;
        allowed
    }

    /// The shared translation `u` of the surface particles' balls: the free surface
    /// particles' mean inertial displacement, unless a surface particle is pinned where it
    /// is, or it would use more than half of what a collider allows some surface particle (a cloth on a table whose edges fall, when it
    /// would only eat the bounds of the particles that touch). Then each keyed pin's
    /// excess: how far it moves over the step apart from `u`.
    fn set_shift(&mut self, p: &Particles, (x, y): (&[Vec3], &[Vec3]), allowed: &[f64]) {
        let n = x.len();
        let topo = &self.topology;
        self.shifted.clear();
        self.shifted
            .extend((0..n).map(|i| topo.surface[i] != u16::MAX));
        let mut sum = Vec3::zeros();
        let mut mass = 0.0;
        let mut room = f64::INFINITY;
        // A pin that stays where it is cannot follow `u` (nor is there room for it to move
        // apart from `u` near it): then no shift.
        let mut still = false;
        for i in (0..n).filter(|&i| self.shifted[i]) {
            if p.is_pinned(i) {
                still |= y[i] == x[i];
            } else {
                sum += (y[i] - x[i]) * p.mass[i];
                mass += p.mass[i];
                room = room.min(allowed[i]);
            }
        }
        let mut u = if still || mass == 0.0 {
            Vec3::zeros()
        } else {
            sum / mass
        };
        // Nor may it close more than half of what a half-space allows a shifted particle:
        // the ball's centre keeps every half-space bound (docs/physics.md §4.1). A sheet
        // lying on a plane shifts along it: the part of `u` into a plane it would close
        // too far is taken out (in particle order), so it slides as a whole.
        for i in (0..n).filter(|&i| self.shifted[i]) {
            for &(_, normal, d) in self.halves[i].iter() {
                let into = -normal.dot(&u);
                if into > 0.5 * GAMMA_COLLIDER * d {
                    u += normal * into;
                }
            }
        }
        let closes_half = (0..n).filter(|&i| self.shifted[i]).any(|i| {
            self.halves[i]
                .iter()
                .any(|&(_, normal, d)| -normal.dot(&u) > 0.5 * GAMMA_COLLIDER * d)
        });
        if u.norm() > 0.5 * room || closes_half {
            u = Vec3::zeros();
        }
        self.shift = u;
        // A pin moves by its keys (its target less where it is; zero when still), exactly:
        // what it moves apart from `u` is room its surface pairs' free sides cannot use.
        self.excess.clear();
        self.excess.extend((0..n).map(|i| {
            if self.shifted[i] && p.is_pinned(i) {
                (y[i] - x[i] - u).norm()
            } else {
                0.0
            }
        }));
    }

    /// Each particle's ball radius (see the module docs): its collider allowance, less the
    /// shared translation for surface particles, and for those also `γ_s` of the room its
    /// nearest surface pair leaves (the pair's distance less its pins' excess), no nearer
    /// than the thickness to the unfelt ones; pairs beyond `reach` are counted at the
    /// reach less twice the largest excess, which the reach was chosen to exceed.
    fn set_radii(&mut self, allowed: Vec<f64>, reach: f64) {
        let n = allowed.len();
        let topo = &self.topology;
        let mut own = std::mem::take(&mut self.scratch_own);
        own.clear();
        own.extend_from_slice(&self.point_surface);
        for (t, (tri, _)) in topo.triangles.iter().enumerate() {
            for &i in tri {
                own[i as usize].meet(&self.triangle_surface[t]);
            }
        }
        for (e, (edge, _)) in topo.edges.iter().enumerate() {
            for &i in edge {
                own[i as usize].meet(&self.edge_surface[e]);
            }
        }
        let pins = self.excess.iter().fold(0.0, |a: f64, &b| a.max(b));
        let unseen = Clearance::new(reach - 2.0 * pins);
        let h_max = self.h_max;
        let shift = self.shift.norm();
        self.bound.clear();
        self.bound.extend((0..n).map(|i| {
            let mut b = allowed[i];
            if self.shifted[i] {
                b -= shift;
                if topo.self_pairs {
                    let mut pairs = own[i];
                    pairs.meet(&unseen);
                    b = b.min(pairs.allows(GAMMA_SURFACE, h_max, 2.0));
                }
            }
            b.max(0.0)
        }));
        self.scratch_own = own;
        self.scratch_allowed = allowed;
    }
}
