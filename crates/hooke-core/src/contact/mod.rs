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
//!    surfaces nearer than `h` (self-collision within a body, less the pairs its own
//!    structure holds apart, `exclusion.rs`; and between bodies), each give
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

mod budgets;
pub(crate) mod crowding;
pub(crate) mod exclusion;
mod gather;
pub(crate) mod grid;
pub mod proximity;
mod respond;
mod stencil;

use crate::collider::Feature;
use crate::collider::response::coulomb_cut;
use crate::model::Model;
use crate::particles::{Particles, Vec3};
use budgets::{Budgets, next_budget};
use crowding::{Caps, Crowded};
use exclusion::{Exclusion, Surfaces};
use gather::{Bins, FeaturePair, Prims, append, pair, par_fill};
use proximity::{feature_gap, point_triangle, segment_segment};
use respond::{FaceSkip, respond_all, respond_one};
use std::time::Instant;
use stencil::{Rule, Stencil};

/// Gauss–Seidel sweeps over the proximities. Proximities that the pushes create are found
/// on the next step, while still a thickness from crossing.
const SWEEPS: usize = 4;
/// Velocity sweeps.
const VELOCITY_SWEEPS: usize = 2;
/// No surface particle.
const NONE: u32 = u32::MAX;

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
    /// The pairs the surfaces' own structure holds apart, never candidates (`exclusion.rs`).
    exclusion: Exclusion,
    /// Largest thickness, and how far beyond it candidates reach.
    h_max: f64,
    skin: f64,
    /// How many candidate pairs surfaces kept apart can hold (`crowding.rs`).
    caps: Caps,
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
    /// The pairs the contact phase skips (empty before its first step).
    pub(crate) fn exclusion(&self) -> &Exclusion {
        &self.exclusion
    }

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

    /// Lists the pairs the surfaces' own structure holds apart, from the rest positions
    /// `rest` (the first step's start): near along the edges within twice the largest
    /// thickness, or one edge apart within it, which this phase would otherwise push apart
    /// at rest or at the first compression of a fine mesh (block descent's bounds reach
    /// further: [`Model::self_contact_skip`]); pairs with a pinned particle are kept.
    fn exclude(&mut self, model: &Model, rest: &[Vec3], p: &Particles) {
        let surface_of = &self.surface_of;
        let surfaces = Surfaces {
            triangles: &self.tris,
            edges: &self.edges,
            self_colliding: &|v| {
                let k = surface_of[v as usize];
                k != NONE && model.surfaces[k as usize].self_collision
            },
            self_pairs: model.surfaces_touch(),
        };
        let (radius, pinned) = (2.0 * self.h_max, |i| p.is_pinned(i as usize));
        self.exclusion = Exclusion::new(&surfaces, rest, (radius, self.h_max), &pinned);
        let thinnest = model
            .active_surfaces()
            .map(|(_, s)| s.thickness)
            .fold(f64::INFINITY, f64::min);
        let prims = (self.points.len(), &self.tris[..], &self.edges[..]);
        self.caps = Caps::new(rest, prims, thinnest, self.reach());
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
    /// Surfaces found crushed through themselves are [`Crowded`] (`crowding.rs`).
    fn refresh(&mut self, model: &Model, x: &[Vec3]) -> Result<(), Crowded> {
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
            return Ok(());
        }
        self.stats.rebuilds += 1;
        self.bin(x);
        if self_stale {
            self.self_ref.clear();
            self.self_ref.extend_from_slice(x);
            if let Err(crowded) = self.build_surface_pairs(model, x) {
                // No list stands for these positions: the next look builds anew.
                self.self_ref.clear();
                return Err(crowded);
            }
        }
        if features_stale {
            self.feature_ref.clear();
            self.feature_ref.extend_from_slice(x);
            self.build_feature_pairs(model, x);
        }
        self.stats.candidates =
            self.point_tri.len() + self.edge_edge.len() + self.feature_pairs.len();
        Ok(())
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
    fn build_surface_pairs(&mut self, model: &Model, x: &[Vec3]) -> Result<(), Crowded> {
        let mut scratch = std::mem::take(&mut self.pair_scratch);
        let reach = self.reach();
        let (mut point_tri, mut edge_edge) = (
            std::mem::take(&mut self.point_tri),
            std::mem::take(&mut self.edge_edge),
        );
        let prims = Prims {
            model,
            skip: &self.exclusion,
            owners: &self.surface_of,
            points: &self.points,
            tris: &self.tris,
            edges: &self.edges,
        };
        let gathered = prims.gather(
            &self.bins,
            x,
            reach,
            self.caps,
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
        gathered
    }

    /// Collider feature–triangle candidates at `x` (after [`ContactState::bin`]).
    fn build_feature_pairs(&mut self, model: &Model, x: &[Vec3]) {
        let reach = self.reach();
        let lists = (&mut self.features, &mut self.feature_pairs);
        gather::feature_pairs(model, (&self.bins, &self.tris), x, reach, lists);
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

/// Runs the contact phase after an integrator step: `x0` are the step's start positions.
/// Returns whether it may have moved any particle, or that the step crushed the surfaces
/// through themselves (`crowding.rs`): then it moved nothing after the colliders' faces.
pub(crate) fn phase(
    model: &Model,
    p: &mut Particles,
    x0: &[Vec3],
    state: &mut ContactState,
) -> Result<bool, Crowded> {
    let started = Instant::now();
    if !state.ready {
        state.prepare(model, p.len());
        if !state.points.is_empty() {
            state.exclude(model, x0, p);
        }
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
        return Ok(moved);
    }
    state.refresh(model, &p.x)?;
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
    Ok(true)
}
