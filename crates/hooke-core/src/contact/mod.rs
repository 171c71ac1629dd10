//! The contact phase that runs after each integrator step: colliders against particles,
//! colliders' sharp features against surface triangles, and surfaces against themselves and
//! each other (the contact model of `docs/physics.md` §3).
//!
//! In the spirit of Bridson, Fedkiw & Anderson (2002), contacts are proximities within a
//! **thickness** `h`, resolved before they become crossings:
//!
//! 1. **Faces.** Every particle is tested against every collider with its body's thickness
//!    as margin and put `h` out of the surface by the collider's response (restitution,
//!    stick); see `respond::respond_all`.
//! 2. **Proximities.** Collider features (mesh edges at an angle, the cylinder's rims)
//!    nearer than `h` to a surface triangle, and particle–triangle and edge–edge pairs of
//!    surfaces nearer than `h` (self-collision within a body, and between bodies), each give
//!    a stencil: weights `w_k` on up to four particles such that `Σ w_k x_k` is the gap
//!    vector. Sweeps of Gauss–Seidel projections in a fixed order push each gap open to
//!    `h` along its normal, sharing the correction by inverse mass (`Δx_k ∝ w_k / m_k`).
//!    Particles moved this way get their face contacts again, so a step ends with every
//!    particle out of every collider.
//! 3. **Velocities.** Each stencil's approaching normal velocity is removed (inelastic),
//!    tangential velocity is cut by Coulomb friction (surfaces) or the collider's response,
//!    again as impulses shared by inverse mass: momentum is kept, kinetic energy can only
//!    drop.
//!
//! The normal of a gap is its direction now, unless the gap closed or flipped during the
//! step (compared with the step's start positions): then the start's direction, so a
//! crossing within one step is undone rather than locked in.
//!
//! Candidates come from a hashed grid (`grid.rs`) and are kept while no surface particle
//! has moved more than half a skin since their build (Verlet lists): pairs of surfaces
//! relative to the surfaces' mean motion (a falling cloth keeps them), pairs with collider
//! features absolutely. A resting cloth costs only its narrow phase. Candidate lists and
//! detection are split into a fixed number of chunks whose results are read in order:
//! results are the same bits on any thread count.

pub(crate) mod grid;
pub mod proximity;
mod respond;

use crate::collider::Feature;
use crate::collider::response::{Response, coulomb_cut};
use crate::model::Model;
use crate::particles::{Particles, Vec3};
use grid::Grid;
use proximity::{
    ball_triangle, circle_triangle, point_triangle, segment_segment, segment_triangle,
};
use rayon::prelude::*;
use respond::{FaceSkip, respond_all, respond_one};
use std::time::Instant;

/// Gauss–Seidel sweeps over the proximities. Proximities that the pushes create are found
/// on the next step, while still a thickness from crossing.
const SWEEPS: usize = 4;
/// Velocity sweeps.
const VELOCITY_SWEEPS: usize = 2;
/// Gaps shorter than this have no direction of their own.
const EPS: f64 = 1e-12;
/// No surface particle.
const NONE: u32 = u32::MAX;

/// How a stencil's velocity responds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Rule {
    /// Surface against surface: inelastic, Coulomb friction with this coefficient.
    Coulomb(f64),
    /// Against a collider with restitution `cr` and Coulomb friction `mu`.
    Bounce { cr: f64, mu: f64 },
    /// Against a stick collider: the touching point stops.
    Stop,
}

impl Rule {
    fn of(response: &Response) -> Self {
        match *response {
            Response::Restitution { cr, friction } => Self::Bounce { cr, mu: friction },
            Response::Stick => Self::Stop,
            Response::Penalty { .. } => Self::Bounce { cr: 0.0, mu: 0.0 },
        }
    }
}

/// A proximity: `Σ w_k x_k - anchor` is the gap between its two sides.
#[derive(Clone, Copy, Debug)]
struct Stencil {
    ids: [u32; 4],
    w: [f64; 4],
    /// 3 (a triangle against a fixed collider point) or 4.
    len: usize,
    /// The collider's point (zero for surface pairs).
    anchor: Vec3,
    /// The collider's velocity at `anchor` over the step (zero for surface pairs and still
    /// colliders).
    anchor_velocity: Vec3,
    /// The gap's unit normal.
    n: Vec3,
    /// The gap to keep, metres.
    h: f64,
    rule: Rule,
}

impl Stencil {
    /// A surface pair: weights `w` on particles `ids`, kept `h` apart, friction `mu`.
    fn surface(ids: [u32; 4], w: [f64; 4], h: f64, mu: f64) -> Self {
        Self {
            ids,
            w,
            len: 4,
            anchor: Vec3::zeros(),
            anchor_velocity: Vec3::zeros(),
            n: Vec3::zeros(),
            h,
            rule: Rule::Coulomb(mu),
        }
    }

    fn gap(&self, x: &[Vec3]) -> Vec3 {
        let mut g = -self.anchor;
        for k in 0..self.len {
            g += x[self.ids[k] as usize] * self.w[k];
        }
        g
    }

    /// `Σ w_k² / m_k`: how far the gap moves per unit impulse.
    fn compliance(&self, inv_mass: &[f64]) -> f64 {
        (0..self.len)
            .map(|k| self.w[k] * self.w[k] * inv_mass[self.ids[k] as usize])
            .sum()
    }

    /// Adds `w_k / m_k · j` to each particle's entry of `y`.
    fn spread(&self, inv_mass: &[f64], y: &mut [Vec3], j: Vec3) {
        for k in 0..self.len {
            let i = self.ids[k] as usize;
            y[i] += j * (self.w[k] * inv_mass[i]);
        }
    }

    /// Orients the stencil at `x` (see the module docs) and returns its signed gap along the
    /// normal, or `None` when no direction can be told.
    fn orient(&mut self, x: &[Vec3], x0: &[Vec3]) -> Option<f64> {
        let now = self.gap(x);
        let start = self.gap(x0);
        let d = now.norm();
        if d > EPS && now.dot(&start) > 0.0 {
            self.n = now / d;
            Some(d)
        } else {
            let d0 = start.norm();
            (d0 > EPS).then(|| {
                self.n = start / d0;
                now.dot(&self.n)
            })
        }
    }
}

/// Contact figures, for benchmarks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactStats {
    /// Wall time spent in the contact phase, seconds, since the simulation began.
    pub seconds: f64,
    /// Candidate lists rebuilt.
    pub rebuilds: u64,
    /// Proximities resolved in the last step.
    pub proximities: usize,
    /// Candidate pairs in the current lists.
    pub candidates: usize,
}

/// A triangle near a collider feature.
#[derive(Clone, Copy, Debug)]
struct FeaturePair {
    tri: u32,
    feature: Feature,
    rule: Rule,
    /// The collider's index (for its velocity).
    collider: u16,
}

/// The contact phase's topology, candidate lists and buffers, kept from step to step.
#[derive(Clone, Debug, Default)]
pub(crate) struct ContactState {
    ready: bool,
    /// Per particle: whether a stick response holds it (see [`respond_all`]).
    /// Sized by [`ContactState::new`], before the first step, because the implicit
    /// integrator reads it.
    pub(crate) held: Vec<bool>,
    /// Per particle: its surface's thickness (empty when no surface has one).
    pub(crate) margin: Vec<f64>,
    /// Per particle: its surface (among the model's), or [`NONE`].
    surface_of: Vec<u32>,
    /// Particles of the active surfaces.
    points: Vec<u32>,
    tris: Vec<[u32; 3]>,
    edges: Vec<[u32; 2]>,
    /// Largest thickness, and how far beyond it candidates reach.
    h_max: f64,
    skin: f64,
    /// Positions at the last build of the surface pairs and of the feature pairs.
    self_ref: Vec<Vec3>,
    feature_ref: Vec<Vec3>,
    point_tri: Vec<[u32; 2]>,
    edge_edge: Vec<[u32; 2]>,
    /// Per candidate: the sum of its particles' [`ContactState::travel`] below which it
    /// cannot be within its thickness (see [`ContactState::detect`]); `-inf` until tested.
    point_tri_budget: Budgets,
    edge_edge_budget: Budgets,
    /// The sum over detections of the largest travel any particle added: no particle's
    /// travel has grown by more than its growth since a block was tested.
    climb: f64,
    /// Per particle: how far it can have moved relative to the surfaces' common motion
    /// since the candidate lists were built, metres (an upper bound: the sum of each leg's
    /// length relative to that leg's mean motion).
    travel: Vec<f64>,
    /// Positions at the last detection.
    x_last: Vec<Vec3>,
    /// The lists were rebuilt since the last detection: travel starts there.
    fresh: bool,
    /// Test every candidate at every detection, budgets or not, and every particle against
    /// every collider (for tests that the skipping changes nothing).
    pub(crate) exhaustive: bool,
    /// Per particle: which collider checks can be skipped (see [`FaceSkip`]).
    pub(crate) face: Vec<FaceSkip>,
    feature_pairs: Vec<FeaturePair>,
    /// Boxes and grids at the last build.
    bins: Bins,
    features: Vec<(Feature, Rule, u16)>,
    active: Vec<Stencil>,
    /// Per-chunk buffers of the parallel detection and candidate builds.
    scratch: Vec<Vec<Stencil>>,
    pair_scratch: Vec<Vec<[u32; 2]>>,
    /// Particles the position sweeps moved.
    moved: Vec<u32>,
    pub(crate) stats: ContactStats,
}

impl ContactState {
    /// The state for `n` particles, none held; the rest is prepared on the first step.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            held: vec![false; n],
            ..Self::default()
        }
    }

    /// Reads the model's surfaces once: per-particle margins and owners, the primitives.
    fn prepare(&mut self, model: &Model, n: usize) {
        self.ready = true;
        let active: Vec<_> = model.active_surfaces().collect();
        if active.is_empty() {
            return;
        }
        self.margin = vec![0.0; n];
        self.surface_of = vec![NONE; n];
        for &(k, s) in &active {
            for p in s.particles.clone() {
                self.margin[p] = s.thickness;
                self.surface_of[p] = k as u32;
                self.points.push(p as u32);
            }
            self.tris.extend(&s.triangles);
            self.edges.extend(s.edges());
            self.h_max = self.h_max.max(s.thickness);
        }
        // Half a skin of travel between builds: a cloth falling a few metres a second
        // rebuilds every few steps, a resting one never.
        self.skin = 2.0 * self.h_max;
    }

    /// The largest displacement of a surface particle from `x_ref`, measured from `shift`
    /// (zero for absolute displacements), squared.
    fn drift2(&self, x: &[Vec3], x_ref: &[Vec3], shift: Vec3) -> f64 {
        self.points
            .iter()
            .map(|&p| (x[p as usize] - x_ref[p as usize] - shift).norm_squared())
            .fold(0.0, f64::max)
    }

    /// Rebuilds whichever candidate lists the motion since their builds may have outdated.
    ///
    /// A pair's distance changes by at most the two particles' displacements relative to any
    /// common shift, so the surface pairs are rebuilt when some particle has moved more than
    /// half a skin relative to the mean motion (a cloth falling as a whole keeps its lists),
    /// the feature pairs when one has moved that far at all (colliders stand still).
    fn refresh(&mut self, model: &Model, x: &[Vec3]) {
        let limit = 0.25 * self.skin * self.skin;
        let self_stale = self.self_ref.is_empty() || {
            let n = self.points.len() as f64;
            let mean = self.points.iter().fold(Vec3::zeros(), |m, &p| {
                m + (x[p as usize] - self.self_ref[p as usize])
            }) / n;
            self.drift2(x, &self.self_ref, mean) > limit
        };
        // A moving collider's features are where it is now: found anew every step.
        let features_stale = self.feature_ref.is_empty()
            || model
                .colliders
                .iter()
                .any(|c| c.shape.is_moving() && c.shape.has_features())
            || self.drift2(x, &self.feature_ref, Vec3::zeros()) > limit;
        if !(self_stale || features_stale) {
            return;
        }
        self.stats.rebuilds += 1;
        self.bin(x);
        if self_stale {
            self.self_ref.clear();
            self.self_ref.extend_from_slice(x);
            self.build_surface_pairs(model, x);
        }
        if features_stale {
            self.feature_ref.clear();
            self.feature_ref.extend_from_slice(x);
            self.build_feature_pairs(model, x);
        }
        self.stats.candidates =
            self.point_tri.len() + self.edge_edge.len() + self.feature_pairs.len();
    }

    /// How far candidates reach: the thickness plus the skin.
    fn reach(&self) -> f64 {
        self.h_max + self.skin
    }

    /// Bins the triangles' and edges' boxes at `x`, grown by the reach (edges by half).
    fn bin(&mut self, x: &[Vec3]) {
        let reach = self.reach();
        self.bins.bin(x, &self.tris, &self.edges, reach);
    }

    /// Particle–triangle and edge–edge candidates at `x` (after [`ContactState::bin`]).
    fn build_surface_pairs(&mut self, model: &Model, x: &[Vec3]) {
        let mut scratch = std::mem::take(&mut self.pair_scratch);
        let reach = self.reach();
        let (mut point_tri, mut edge_edge) = (
            std::mem::take(&mut self.point_tri),
            std::mem::take(&mut self.edge_edge),
        );
        let prims = Prims {
            model,
            owners: &self.surface_of,
            points: &self.points,
            tris: &self.tris,
            edges: &self.edges,
        };
        prims.gather(
            &self.bins,
            x,
            reach,
            &mut scratch,
            &mut point_tri,
            &mut edge_edge,
        );
        self.point_tri = point_tri;
        self.edge_edge = edge_edge;
        self.pair_scratch = scratch;
        // New lists: every candidate is tested at the next detection, and travel is
        // counted from here.
        self.point_tri_budget.reset(self.point_tri.len());
        self.edge_edge_budget.reset(self.edge_edge.len());
        self.travel.clear();
        self.travel.resize(x.len(), 0.0);
        self.fresh = true;
    }

    /// Collider feature–triangle candidates at `x` (after [`ContactState::bin`]).
    fn build_feature_pairs(&mut self, model: &Model, x: &[Vec3]) {
        let reach = self.reach();
        self.feature_pairs.clear();
        self.features.clear();
        if self.tris.is_empty() {
            return;
        }
        let (lo, hi) = self.bins.tri_box.iter().fold(
            (self.bins.tri_box[0].0, self.bins.tri_box[0].1),
            |(lo, hi), b| (lo.inf(&b.0), hi.sup(&b.1)),
        );
        for (k, slot) in model.colliders.iter().enumerate() {
            if !slot.shape.has_features() {
                continue;
            }
            let rule = Rule::of(&slot.response);
            let features = &mut self.features;
            slot.shape
                .features(&lo, &hi, &mut |f| features.push((f, rule, k as u16)));
        }
        for &(feature, rule, collider) in &self.features {
            let (flo, fhi) = feature.bounds();
            let (c0, c1) = (
                self.bins.tri_grid.cell_of(&flo),
                self.bins.tri_grid.cell_of(&fhi),
            );
            for i in c0[0] - 1..=c1[0] {
                for j in c0[1] - 1..=c1[1] {
                    for k in c0[2] - 1..=c1[2] {
                        let (boxes, pairs) = (&self.bins.tri_box, &mut self.feature_pairs);
                        let tris = &self.tris;
                        self.bins.tri_grid.visit([i, j, k], |t| {
                            let b = &boxes[t as usize];
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
        self.feature_pairs.sort_by_key(|p| p.tri);
    }

    /// Adds to every surface particle's travel the path since the last detection: the leg
    /// to this step's start `x0` (the last step's pushes) and the leg to `x` (this step's
    /// integration), each measured from that leg's mean motion over the surface particles.
    /// A pair's gap does not change under a motion common to all particles, so between two
    /// detections it changes by at most the sum of its particles' travel.
    fn advance_travel(&mut self, x: &[Vec3], x0: &[Vec3]) {
        if self.fresh || self.x_last.len() != x.len() {
            self.fresh = false;
        } else {
            let n = self.points.len() as f64;
            let (mut push, mut step) = (Vec3::zeros(), Vec3::zeros());
            for &p in &self.points {
                let p = p as usize;
                push += x0[p] - self.x_last[p];
                step += x[p] - x0[p];
            }
            let (push, step) = (push / n, step / n);
            let mut most = 0.0_f64;
            for &p in &self.points {
                let p = p as usize;
                let leg = (x0[p] - self.x_last[p] - push).norm() + (x[p] - x0[p] - step).norm();
                self.travel[p] += leg;
                most = most.max(leg);
            }
            self.climb += most;
        }
        self.x_last.clear();
        self.x_last.extend_from_slice(x);
    }

    /// Appends to `active` every candidate whose gap is under its thickness at `x`, in
    /// candidate order.
    ///
    /// A surface pair found at distance `d` at a detection, when its particles' travel
    /// summed to `T`, stays farther than its thickness `h` while that sum stays below
    /// `T + d - h`: each particle's travel bounds its motion relative to the common motion,
    /// and a common motion leaves the gap alone. Its gap at the step's start is then also
    /// farther than `h` and on the same side (the last leg is part of the travel), so
    /// [`Stencil::orient`] would give a distance of at least `h` and the pair would not be
    /// kept: it is not tested until then, and the pairs kept are those a test of every
    /// candidate keeps.
    fn detect(&mut self, model: &Model, x: &[Vec3], x0: &[Vec3]) {
        let mut scratch = std::mem::take(&mut self.scratch);
        let keep = |mut s: Stencil, out: &mut Vec<Stencil>| {
            if s.orient(x, x0).is_some_and(|d| d < s.h) {
                out.push(s);
            }
        };
        par_fill(self.feature_pairs.len(), &mut scratch, |i, out| {
            let pair = &self.feature_pairs[i];
            let t = self.tris[pair.tri as usize];
            let h = self.margin[t[0] as usize];
            if let Some((anchor, w)) = feature_gap(&pair.feature, &t, x, h) {
                let shape = &model.colliders[pair.collider as usize].shape;
                let s = Stencil {
                    ids: [t[0], t[1], t[2], 0],
                    w: [w[0], w[1], w[2], 0.0],
                    len: 3,
                    anchor,
                    anchor_velocity: shape.velocity(&anchor),
                    n: Vec3::zeros(),
                    h,
                    rule: pair.rule,
                };
                keep(s, out);
            }
        });
        append(&mut self.active, &scratch);
        self.advance_travel(x, x0);
        // A tested pair: its new budget, kept if within its thickness; the budget left.
        let settle = |s: Stencil, moved: f64, budget: &mut f64, out: &mut Vec<Stencil>| {
            *budget = next_budget(&s, x, moved);
            keep(s, out);
            *budget - moved
        };
        let travel = &self.travel;
        // Exhaustive: no climb, so no block is skipped, and no pair either.
        let climb = (!self.exhaustive).then_some(self.climb);
        let skip = climb.is_some();
        let mut budgets = std::mem::take(&mut self.point_tri_budget);
        budgets.run(&mut scratch, climb, |i, budget, out| {
            let [p, t] = self.point_tri[i];
            let tri = self.tris[t as usize];
            let moved = travel[p as usize]
                + travel[tri[0] as usize]
                + travel[tri[1] as usize]
                + travel[tri[2] as usize];
            if skip && moved < *budget {
                return *budget - moved;
            }
            let Some((h, mu)) = pair(model, &self.surface_of, p, tri[0]) else {
                *budget = f64::INFINITY;
                return f64::INFINITY;
            };
            let [ia, ib, ic] = tri.map(|i| i as usize);
            let w = point_triangle(&x[p as usize], &x[ia], &x[ib], &x[ic]);
            let ids = [p, tri[0], tri[1], tri[2]];
            let s = Stencil::surface(ids, [1.0, -w[0], -w[1], -w[2]], h, mu);
            settle(s, moved, budget, out)
        });
        self.point_tri_budget = budgets;
        append(&mut self.active, &scratch);
        let mut budgets = std::mem::take(&mut self.edge_edge_budget);
        budgets.run(&mut scratch, climb, |i, budget, out| {
            let [e, f] = self.edge_edge[i];
            let (ee, ef) = (self.edges[e as usize], self.edges[f as usize]);
            let moved = travel[ee[0] as usize]
                + travel[ee[1] as usize]
                + travel[ef[0] as usize]
                + travel[ef[1] as usize];
            if skip && moved < *budget {
                return *budget - moved;
            }
            let Some((h, mu)) = pair(model, &self.surface_of, ee[0], ef[0]) else {
                *budget = f64::INFINITY;
                return f64::INFINITY;
            };
            let [a, b] = ee.map(|i| x[i as usize]);
            let [c, d] = ef.map(|i| x[i as usize]);
            let (s, t) = segment_segment(&a, &b, &c, &d);
            let ids = [ee[0], ee[1], ef[0], ef[1]];
            let st = Stencil::surface(ids, [1.0 - s, s, t - 1.0, -t], h, mu);
            settle(st, moved, budget, out)
        });
        self.edge_edge_budget = budgets;
        append(&mut self.active, &scratch);
        self.scratch = scratch;
    }
}

/// A model's contact primitives, for gathering candidate pairs.
struct Prims<'a> {
    model: &'a Model,
    owners: &'a [u32],
    points: &'a [u32],
    tris: &'a [[u32; 3]],
    edges: &'a [[u32; 2]],
}

impl Prims<'_> {
    /// Replaces `point_tri` and `edge_edge` with the particle–triangle and edge–edge pairs of
    /// surfaces that collide nearer than `reach` at `x`, found through `bins` (binned at `x`
    /// with that reach): by particle, then by the particle's cells and triangle; by edge,
    /// then by the edge's cells and the other edge.
    fn gather(
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
struct Bins {
    tri_box: Vec<(Vec3, Vec3)>,
    edge_box: Vec<(Vec3, Vec3)>,
    tri_grid: Grid,
    edge_grid: Grid,
}

impl Bins {
    /// Bins the boxes of `tris` and `edges` at `x`, grown by `reach` (edges by half), in
    /// cells at least as large as the reach and every box.
    fn bin(&mut self, x: &[Vec3], tris: &[[u32; 3]], edges: &[[u32; 2]], reach: f64) {
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
const CHUNKS: usize = 8;
/// Fewer candidates than this are not worth a parallel pass.
const PARALLEL_MIN: usize = 512;

/// Calls `f(i, out)` for every `i < n`, filling `bufs` (one per chunk of consecutive
/// indices, [`CHUNKS`] of them) in parallel; reading the buffers in order gives what a
/// sequential pass would have pushed.
fn par_fill<U: Send>(
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
fn append<U: Copy>(dst: &mut Vec<U>, bufs: &[Vec<U>]) {
    for b in bufs {
        dst.extend_from_slice(b);
    }
}

/// The travel sum up to which a pair tested at `x`, with its particles' travel summing to
/// `moved`, cannot come within its thickness: `moved + d - h` less a margin for rounding
/// (relative to the distances and travel involved), or `-inf` when it is within it now.
fn next_budget(s: &Stencil, x: &[Vec3], moved: f64) -> f64 {
    let d = s.gap(x).norm();
    let slack = d - s.h - 1e-6 * (d + moved) - 1e-9;
    if slack > 0.0 {
        moved + slack
    } else {
        f64::NEG_INFINITY
    }
}

/// Candidates tested together: a block is skipped whole while no candidate in it can have
/// used up its budget.
const BLOCK: usize = 64;

/// A block of candidates: the climb when it was last tested, and the smallest budget left
/// (budget less the travel sum) among its candidates then.
#[derive(Clone, Copy, Debug)]
struct Block {
    climb: f64,
    left: f64,
}

impl Block {
    const UNTESTED: Self = Self {
        climb: 0.0,
        left: f64::NEG_INFINITY,
    };
}

/// A candidate list's budgets: one per candidate (see [`ContactState::detect`]), and per
/// block of [`BLOCK`] candidates when it was last tested and its least budget left.
#[derive(Clone, Debug, Default)]
struct Budgets {
    per_pair: Vec<f64>,
    blocks: Vec<Block>,
}

impl Budgets {
    /// Budgets for a new list of `n` candidates: every one untested.
    fn reset(&mut self, n: usize) {
        self.per_pair.clear();
        self.per_pair.resize(n, f64::NEG_INFINITY);
        self.blocks.clear();
        self.blocks.resize(n.div_ceil(BLOCK), Block::UNTESTED);
    }

    /// [`par_blocks`] over these budgets.
    fn run<U: Send>(
        &mut self,
        bufs: &mut Vec<Vec<U>>,
        climb: Option<f64>,
        f: impl Fn(usize, &mut f64, &mut Vec<U>) -> f64 + Sync + Send,
    ) {
        par_blocks(bufs, &mut self.per_pair, &mut self.blocks, climb, f);
    }
}

/// Calls `f(i, &mut budget[i], out)` for every candidate of a block that may have used up
/// its budget, in [`CHUNKS`] parallel chunks of whole blocks whose outputs read in order give
/// what a sequential pass pushes; `f` returns the candidate's budget left. A block is
/// skipped while four times the climb since its test (a bound on any candidate's travel
/// sum's growth: four particles, none of whose travel grew by more than the climb) is below
/// the least budget left in it; with `climb` `None` no block is skipped.
fn par_blocks<U: Send>(
    bufs: &mut Vec<Vec<U>>,
    budgets: &mut [f64],
    blocks: &mut [Block],
    climb: Option<f64>,
    f: impl Fn(usize, &mut f64, &mut Vec<U>) -> f64 + Sync + Send,
) {
    // `None`: test every block.
    let (climb, skip) = (climb.unwrap_or(0.0), climb.is_some());
    bufs.resize_with(CHUNKS, Vec::new);
    for b in bufs.iter_mut() {
        b.clear();
    }
    let run = |first: usize, budgets: &mut [f64], blocks: &mut [Block], out: &mut Vec<U>| {
        for (k, (chunk, block)) in budgets.chunks_mut(BLOCK).zip(blocks).enumerate() {
            if skip && 4.0 * (climb - block.climb) < block.left {
                continue;
            }
            let start = first + k * BLOCK;
            let mut left = f64::INFINITY;
            for (j, budget) in chunk.iter_mut().enumerate() {
                left = left.min(f(start + j, budget, out));
            }
            *block = Block { climb, left };
        }
    };
    let n = budgets.len();
    if n < PARALLEL_MIN {
        run(0, budgets, blocks, &mut bufs[0]);
        return;
    }
    let per = blocks.len().div_ceil(CHUNKS);
    bufs.par_iter_mut()
        .zip(
            budgets
                .par_chunks_mut(per * BLOCK)
                .zip(blocks.par_chunks_mut(per)),
        )
        .enumerate()
        .for_each(|(k, (out, (budgets, blocks)))| run(k * per * BLOCK, budgets, blocks, out));
}

/// The closest points of a collider feature and triangle `t` at `x`: the feature's point
/// and the triangle's barycentric weights; `None` when a cheap bound shows they are farther
/// apart than `within`.
fn feature_gap(
    feature: &Feature,
    t: &[u32; 3],
    x: &[Vec3],
    within: f64,
) -> Option<(Vec3, [f64; 3])> {
    let (a, b, c) = (&x[t[0] as usize], &x[t[1] as usize], &x[t[2] as usize]);
    let (anchor, w) = match feature {
        Feature::Segment([p, q]) => {
            let (s, w) = segment_triangle(p, q, a, b, c);
            (p + (q - p) * s, w)
        }
        Feature::Circle(circle) if circle.distance_bound(a, b, c) >= within => return None,
        Feature::Circle(circle) => circle_triangle(circle, a, b, c),
        Feature::Ball { center, radius } => ball_triangle(center, *radius, a, b, c),
    };
    let gap = a * w[0] + b * w[1] + c * w[2] - anchor;
    (gap.norm_squared() < within * within).then_some((anchor, w))
}

/// Whether `p` lies in the box.
fn inside(p: &Vec3, (lo, hi): &(Vec3, Vec3)) -> bool {
    (0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k])
}

/// Whether two boxes overlap.
fn overlap((a0, a1): &(Vec3, Vec3), (b0, b1): &(Vec3, Vec3)) -> bool {
    (0..3).all(|k| a0[k] <= b1[k] && b0[k] <= a1[k])
}

/// Whether particles `a` and `b` (both on active surfaces) collide: their surfaces differ
/// or share self-collision; with the pair's thickness (the larger) and friction (the mean).
fn pair(model: &Model, surface_of: &[u32], a: u32, b: u32) -> Option<(f64, f64)> {
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

/// Runs the contact phase after an integrator step: `x0` are the step's start positions.
/// Returns whether it may have moved any particle.
pub(crate) fn phase(
    model: &Model,
    p: &mut Particles,
    x0: &[Vec3],
    state: &mut ContactState,
) -> bool {
    let started = Instant::now();
    if !state.ready {
        state.prepare(model, p.len());
    }
    let held = &mut state.held;
    if state.face.len() != p.len() {
        let skip = if state.exhaustive {
            FaceSkip::NEVER
        } else {
            FaceSkip::default()
        };
        state.face = vec![skip; p.len()];
    }
    let face = &mut state.face;
    let moved = respond_all(
        model,
        &p.inv_mass,
        &state.margin,
        x0,
        &mut p.x,
        &mut p.v,
        held,
        face,
    );
    if state.points.is_empty() {
        state.stats.seconds += started.elapsed().as_secs_f64();
        return moved;
    }
    state.refresh(model, &p.x);
    state.active.clear();
    state.detect(model, &p.x, x0);
    for _ in 0..SWEEPS {
        for s in &state.active {
            let d = s.gap(&p.x).dot(&s.n);
            if d >= s.h {
                continue;
            }
            let c = s.compliance(&p.inv_mass);
            if c == 0.0 {
                continue;
            }
            s.spread(&p.inv_mass, &mut p.x, s.n * ((s.h - d) / c));
            let moved = (0..s.len)
                .filter(|&k| s.w[k] != 0.0 && p.inv_mass[s.ids[k] as usize] != 0.0)
                .map(|k| s.ids[k]);
            state.moved.extend(moved);
        }
    }
    // Pushed particles may now be in a collider: their face contacts again, once each and
    // in order, so that a step always ends with every particle out of every collider.
    if model.has_contact_responses() {
        state.moved.sort_unstable();
        state.moved.dedup();
        for &i in &state.moved {
            let i = i as usize;
            let (x, v) = (&mut p.x[i], &mut p.v[i]);
            let held = &mut state.held[i];
            *held = respond_one(
                model,
                p.inv_mass[i],
                state.margin[i],
                &x0[i],
                x,
                v,
                *held,
                None,
            );
        }
    }
    state.moved.clear();
    for _ in 0..VELOCITY_SWEEPS {
        for s in &state.active {
            let c = s.compliance(&p.inv_mass);
            if c == 0.0 {
                continue;
            }
            // The gap's velocity: the stencil's, less the collider point's.
            let mut u = s.gap(&p.v) + s.anchor;
            if s.anchor_velocity != Vec3::zeros() {
                u -= s.anchor_velocity;
            }
            let un = u.dot(&s.n);
            let ut = u - s.n * un;
            let du = match s.rule {
                Rule::Stop => -u,
                _ if un >= 0.0 => continue,
                Rule::Bounce { cr, mu } => {
                    let dvn = -(1.0 + cr) * un;
                    s.n * dvn - ut * coulomb_cut(mu, dvn, &ut)
                }
                Rule::Coulomb(mu) => s.n * -un - ut * coulomb_cut(mu, -un, &ut),
            };
            s.spread(&p.inv_mass, &mut p.v, du / c);
        }
    }
    state.stats.proximities = state.active.len();
    state.stats.seconds += started.elapsed().as_secs_f64();
    true
}
