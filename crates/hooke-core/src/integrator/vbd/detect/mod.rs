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
//! step size: the integrator can fail to converge, never cross. The pairs of one surface
//! that its own springs hold apart (`contact/exclusion.rs`: within the reach of each other at
//! rest, and along the surface or neighbours) are not searched and bound nothing: the argument does not cover
//! them, and a crease that brings such a pair within a thickness can cross.

mod colliders;

pub(in crate::integrator) use colliders::collider_law;

use super::candidates::{Candidates, SKIN, search};
use super::graph::Graph;
use super::pairs::{Pair, Sides, stencil_distance};
use super::planes::{Lists, Plane};
use super::topology::Topology;
use crate::collider::response::Response;
use crate::contact::exclusion::Exclusion;
use crate::model::Model;
use crate::particles::{Particles, Vec3};

/// Share of a surface-to-surface distance each side may use up: below one half.
pub(crate) const GAMMA_SURFACE: f64 = 0.4;
/// Share of a distance to a collider a particle may use up: below one.
pub(crate) const GAMMA_COLLIDER: f64 = 0.9;
/// Reach of the search between surfaces, in thicknesses.
const SURFACE_REACH: f64 = 4.0;
// The skipped pairs cover the search's reach at rest, so that no neighbour bounds a flat
// sheet's particles.
const _: () = assert!(crate::model::SELF_CONTACT_SKIP >= SURFACE_REACH);
/// Least reach of the search for colliders, in thicknesses.
const COLLIDER_REACH: f64 = 10.0;
/// Pairs nearer than this many thicknesses are felt until the next detection; farther ones
/// bound the motion instead, so that they cannot come within a thickness unfelt.
const FELT: f64 = 2.0;
/// Contact stiffness as a multiple of a particle's own stiffness scale `m/dt² + Σ ks`.
pub(crate) const CONTACT_STIFFNESS: f64 = 1.0;

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

/// Into `out`, each particle's clearance (`particles`) met with its triangles'.
fn per_particle(
    topo: &Topology,
    (particles, triangles): (&[Clearance], &[Clearance]),
    out: &mut Vec<Clearance>,
) {
    out.clear();
    out.extend_from_slice(particles);
    for (t, (tri, _)) in topo.triangles.iter().enumerate() {
        for &i in tri {
            out[i as usize].meet(&triangles[t]);
        }
    }
}

/// The result of a detection, and its buffers.
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Detection {
    topology: Topology,
    /// Positions at the first step: pairs nearer than their gap there are neighbours in the
    /// body's own rest shape, not contacts.
    rest: Vec<Vec3>,
    /// The pairs the surfaces' own structure holds apart, never measured (`contact/exclusion.rs`).
    exclusion: Exclusion,
    /// Per particle: the collider surfaces it may reach before the next detection, each as
    /// its tangent plane at the detection.
    pub(in crate::integrator) touches: Lists<Plane>,
    /// Per particle: the half-space colliders near it, which bound only the motion that
    /// closes its gap to them.
    pub(in crate::integrator) halves: Lists<(Vec3, Vec3, f64)>,
    /// The collider search's per-chunk results, kept for their buffers.
    found: Vec<colliders::Found>,
    /// The feature search's per-chunk results, kept for their buffers.
    features_found: Vec<colliders::FeaturesFound>,
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
    /// The pair list's builds so far, and their time.
    builds: (u64, std::time::Duration),
    /// The largest thickness of the active surfaces.
    h_max: f64,
    /// Per particle: how far a pinned surface particle moves over the step apart from the
    /// shared translation, `|c - u|` (`c` its keyed displacement); zero for the rest.
    excess: Vec<f64>,
    /// Per particle: its stiffness scale `m/dt² + Σ ks`.
    pub(in crate::integrator) scale: Vec<f64>,
}

/// Where a detection centres its balls.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::integrator) enum Centres {
    /// At the detected points moved by the step's shared translation `u` (see
    /// `set_shift`): a falling sheet's balls fall with it. A ball may then leave out its
    /// own detected point (where its nearest pair allows less than `u`), and every
    /// update of that particle is taken into it, whatever its forces ask.
    Shifted,
    /// At the detected points: each ball holds its own, so that staying put is always
    /// allowed (what a line search from the current iterate needs).
    Detected,
}

impl Detection {
    /// The pairs the surfaces' own structure holds apart (empty before the first detection).
    pub(in crate::integrator) fn exclusion(&self) -> &Exclusion {
        &self.exclusion
    }

    /// The pair list's builds so far, and the time they took.
    pub(in crate::integrator) fn builds(&self) -> (u64, std::time::Duration) {
        self.builds
    }

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
        !self.touches.is_empty_at(i) || self.start[i] != self.start[i + 1]
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
    /// (which set how far the search reaches and, with [`Centres::Shifted`], the shared
    /// translation `u`).
    pub(in crate::integrator) fn detect(
        &mut self,
        model: &Model,
        p: &Particles,
        graph: &Graph,
        (x, y): (&[Vec3], &[Vec3]),
        (dt, centres): (f64, Centres),
    ) {
        let n = x.len();
        let h_max = model
            .active_surfaces()
            .map(|(_, s)| s.thickness)
            .fold(0.0, f64::max);
        if self.topology.built_for != n || self.rest.len() != n {
            self.topology = Topology::new(model, n);
            self.rest = x.to_vec();
            // Pairs one edge apart only where they start within the thickness: a sliver's.
            let reach = (model.self_contact_skip(), h_max);
            let pinned = |i: u32| p.is_pinned(i as usize);
            self.exclusion = self.topology.exclusion(&self.rest, reach, &pinned);
        }
        self.scale.clear();
        self.scale
            .extend((0..n).map(|i| p.mass[i] / (dt * dt) + graph.stiffness[i]));
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
        match centres {
            Centres::Shifted => self.set_shift(p, (x, y), &allowed),
            Centres::Detected => self.keep_still(p, (x, y)),
        }
        // Surfaces are searched far enough that pairs beyond the reach stay apart however
        // far keyed pins move from the shared translation (see `set_radii`).
        let pins = self.excess.iter().fold(0.0, |a: f64, &b| a.max(b));
        let surface_reach = (SURFACE_REACH * h_max).max(4.0 * pins);
        self.detect_surfaces(model, x, surface_reach);
        self.index_pairs(n, p);
        self.mark_touching_bodies(graph);
        self.set_radii(allowed, surface_reach);
    }

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
            // The old list goes before the new one is searched: the two at once were the
            // block-descent step's peak memory.
            let started = std::time::Instant::now();
            self.candidates.forget();
            let built = reach + SKIN * reach;
            let (point_tri, edge_edge) = search((topo, &self.exclusion), x, built);
            self.candidates.rebuild(built, point_tri, edge_edge);
            self.builds.0 += 1;
            self.builds.1 += started.elapsed();
        }
        let (found, found_edges) = self.candidates.within(topo, x, reach);
        for (v, t, d) in found {
            let Some((h, mu)) = law(topo.surface[v as usize], topo.triangles[t as usize].1) else {
                continue;
            };
            let v = v as usize;
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

        for (e, f, d) in found_edges {
            let Some((h, mu)) = law(topo.edges[e as usize].1, topo.edges[f as usize].1) else {
                continue;
            };
            let (e, f) = (e as usize, f as usize);
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
        per_particle(
            topo,
            (&self.point_collider, &self.triangle_collider),
            &mut collider,
        );
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
            for &(_, normal, d) in self.halves.of(i) {
                let into = -normal.dot(&u);
                if into > 0.5 * GAMMA_COLLIDER * d {
                    u += normal * into;
                }
            }
        }
        let closes_half = (0..n).filter(|&i| self.shifted[i]).any(|i| {
            self.halves
                .of(i)
                .iter()
                .any(|&(_, normal, d)| -normal.dot(&u) > 0.5 * GAMMA_COLLIDER * d)
        });
        if u.norm() > 0.5 * room || closes_half {
            u = Vec3::zeros();
        }
        self.set_excess(p, (x, y), u);
    }

    /// No shared translation: every ball is centred where its particle was detected, so
    /// that it holds that point.
    fn keep_still(&mut self, p: &Particles, (x, y): (&[Vec3], &[Vec3])) {
        self.set_excess(p, (x, y), Vec3::zeros());
    }

    /// Sets the shared translation `u` and each keyed pin's excess over it.
    fn set_excess(&mut self, p: &Particles, (x, y): (&[Vec3], &[Vec3]), u: Vec3) {
        let n = x.len();
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
        per_particle(
            topo,
            (&self.point_surface, &self.triangle_surface),
            &mut own,
        );
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
