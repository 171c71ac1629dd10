//! The force model of a system: everything that is constant during a run.

use crate::air::{AeroSurface, Air};
use crate::collider::{Collider, Contact};
use crate::force_field::ForceField;
use crate::parallel;
use crate::particles::Vec3;
use crate::response::Response;
use crate::spring::Spring;
use crate::surface::Surface;

/// A collider together with the response it triggers.
#[derive(Debug)]
pub struct ColliderSlot {
    /// The shape.
    pub shape: Box<dyn Collider>,
    /// What it does to particles that violate it.
    pub response: Response,
}

/// Springs, external forces and colliders, and the per-particle masses they act on.
///
/// Forces are evaluated per docs/physics.md §1 by an [`crate::Assembly`], which sums them in an order
/// fixed by the problem, so results are the same bits however the work is split.
#[derive(Debug, Default)]
pub struct Model {
    /// Every spring of the system.
    pub springs: Vec<Spring>,
    /// Gravitational acceleration in m/s², applied as the force `m g`.
    pub gravity: Vec3,
    /// Linear drag in N·s/m (force `-drag v` on every particle); zero disables it.
    pub drag: f64,
    /// An optional force field (jello worlds).
    pub field: Option<ForceField>,
    /// Colliders, each with its response.
    pub colliders: Vec<ColliderSlot>,
    /// Particles tied to points in space, such as a particle grabbed with the mouse.
    pub attachments: Vec<Attachment>,
    /// The bodies' surfaces that take part in contacts (see [`crate::contact`]); empty for
    /// systems of bare particles, whose contacts are the per-particle tests of docs/physics.md §3.3 alone.
    pub surfaces: Vec<Surface>,
    /// The air the system moves in; `None` for vacuum (no drag or lift beyond `drag`).
    pub air: Option<Air>,
    /// The bodies' triangles that air acts on, with their coefficients (only read when
    /// `air` is set).
    pub aero: Vec<AeroSurface>,
}

/// A zero-length damped spring from a particle to a point in space: the force
/// `-ks (x - target) - kd v`. The viewer's grab is one; the target may move between steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attachment {
    /// The particle held.
    pub particle: usize,
    /// Where it is pulled, metres.
    pub target: Vec3,
    /// Stiffness, N/m.
    pub ks: f64,
    /// Damping, N·s/m.
    pub kd: f64,
}

/// Which of a model's penalty colliders may touch a group of particles (see
/// [`Model::near`]): bit `k` for collider `k`; colliders past the 64th are always asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Near(u64);

impl Near {
    /// Every collider may touch.
    pub const ALL: Self = Self(u64::MAX);

    /// Whether collider `k` may touch.
    #[inline]
    pub fn may_touch(self, k: usize) -> bool {
        k >= 64 || self.0 >> k & 1 == 1
    }
}

/// Colliders with a velocity response whose checks [`FaceSkip`] tracks per particle; any
/// further ones are checked every step.
pub(crate) const FACE_SKIP_COLLIDERS: usize = 4;

/// Radii of the boxes around a particle tried, largest first, for a collider it cannot
/// touch within them (metres).
const CLEARANCES: [f64; 3] = [0.2, 0.05, 0.0125];

/// One particle's record for skipping collider checks that cannot find anything: its
/// path length (the sum of every leg's length between checks: a bound on how far it can
/// have moved since any earlier check), where it was at the last check, and per tracked
/// collider the path length below which it cannot reach it (`-inf`: check).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FaceSkip {
    /// `false`: check every collider every time.
    enabled: bool,
    path: f64,
    last: Vec3,
    budget: [f64; FACE_SKIP_COLLIDERS],
}

impl Default for FaceSkip {
    fn default() -> Self {
        Self {
            enabled: true,
            ..Self::NEVER
        }
    }
}

impl FaceSkip {
    /// Skips nothing.
    pub(crate) const NEVER: Self = Self {
        enabled: false,
        path: 0.0,
        last: Vec3::new(f64::NAN, f64::NAN, f64::NAN),
        budget: [f64::NEG_INFINITY; FACE_SKIP_COLLIDERS],
    };

    /// The budget after a check at `here` that found nothing: the largest of
    /// [`CLEARANCES`] whose box around `here` the collider promises not to touch within
    /// `margin` ([`Collider::may_touch`]), less how far `here` lies from where the path
    /// was last counted (`counted`), and a little for rounding.
    fn clearance(&self, shape: &dyn Collider, here: &Vec3, counted: &Vec3, margin: f64) -> f64 {
        let shift = (here - counted).norm();
        for r in CLEARANCES {
            if !shape.may_touch(&here.add_scalar(-r), &here.add_scalar(r), margin) {
                return self.path + 0.999 * r - shift - 1e-9;
            }
        }
        f64::NEG_INFINITY
    }
}

/// Particles per parallel block of collision responses.
const CONTACT_BLOCK: usize = 256;

impl Model {
    /// Whether gravity is the only force besides the springs (no field, drag, air, penalty
    /// colliders or attachments): integrators then use a loop without the per-particle
    /// tests of [`Model::external_force`], whose result it equals to the bit.
    pub fn gravity_only(&self) -> bool {
        self.field.is_none()
            && self.drag == 0.0
            && self.air.is_none()
            && self.attachments.is_empty()
            && self.colliders.iter().all(|c| !c.response.is_force())
    }

    /// Whether any collider has a velocity-level response (restitution, stick), which
    /// `Model::resolve_contacts` applies after each step from the step's start positions.
    pub fn has_contact_responses(&self) -> bool {
        self.colliders.iter().any(|c| !c.response.is_force())
    }

    /// Whether the contact phase after each step has work: velocity-level responses or
    /// surfaces with a thickness. It reads the step's start positions.
    pub fn has_contact_phase(&self) -> bool {
        self.has_contact_responses() || self.surfaces.iter().any(Surface::is_active)
    }

    /// The surfaces with a thickness (whose contacts are on), with their indices.
    pub(crate) fn active_surfaces(&self) -> impl Iterator<Item = (usize, &Surface)> {
        self.surfaces
            .iter()
            .enumerate()
            .filter(|(_, s)| s.is_active())
    }

    /// The contact thickness of particle `p`: its surface's, zero for particles outside
    /// every surface.
    #[inline]
    pub fn margin(&self, p: usize) -> f64 {
        self.surfaces
            .iter()
            .find(|s| s.particles.contains(&p))
            .map_or(0.0, |s| s.thickness)
    }

    /// The total force on particle `p` at `(x, v)`, given `springs`, the sum of its springs'
    /// forces: external forces, attachments and springs.
    #[inline]
    pub fn total_force(&self, p: usize, mass: f64, x: &Vec3, v: &Vec3, springs: Vec3) -> Vec3 {
        self.total_force_near(p, (mass, x, v), springs, Near::ALL)
    }

    /// [`Model::total_force`] asking only the penalty colliders `near` may let touch.
    #[inline]
    pub fn total_force_near(
        &self,
        p: usize,
        (mass, x, v): (f64, &Vec3, &Vec3),
        springs: Vec3,
        near: Near,
    ) -> Vec3 {
        let f = self.external_force_near(p, mass, x, v, near) + springs;
        if self.attachments.is_empty() {
            f
        } else {
            f + self.attachment_force(p, x, v)
        }
    }

    /// The penalty colliders that may touch some particle at positions `x`: those whose
    /// [`Collider::may_touch`] holds for the particles' bounding box, at the largest contact
    /// thickness of any surface. Forces computed with the answer are the same bits as
    /// without it; only the colliders' answers for particles they cannot touch are skipped.
    pub fn near(&self, x: &[Vec3]) -> Near {
        if self.colliders.iter().all(|c| !c.response.is_force()) {
            return Near::ALL;
        }
        // Component by component: nalgebra's `inf`/`sup` cost three times as much here.
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in x {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
        let margin = self
            .surfaces
            .iter()
            .map(|s| s.thickness)
            .fold(0.0, f64::max);
        let mut bits = u64::MAX;
        for (k, slot) in self.colliders.iter().enumerate().take(64) {
            if slot.response.is_force() && !slot.shape.may_touch(&lo, &hi, margin) {
                bits &= !(1 << k);
            }
        }
        Near(bits)
    }

    /// Whether gravity is the only force besides the springs on particles whose penalty
    /// colliders are `near` (see [`Model::gravity_only`]): then [`Model::total_force_near`]
    /// is `m g + springs`, to the bit.
    pub fn gravity_only_near(&self, near: Near) -> bool {
        self.field.is_none()
            && self.drag == 0.0
            && self.attachments.is_empty()
            && self
                .colliders
                .iter()
                .enumerate()
                .all(|(k, c)| !c.response.is_force() || !near.may_touch(k))
    }

    /// Every force on particle `p` except its springs': gravity, field, drag, penalties (with
    /// the particle's contact thickness as the penalty springs' margin).
    #[inline]
    pub fn external_force(&self, p: usize, mass: f64, x: &Vec3, v: &Vec3) -> Vec3 {
        self.external_force_near(p, mass, x, v, Near::ALL)
    }

    /// [`Model::external_force`] asking only the penalty colliders `near` may let touch.
    #[inline]
    pub fn external_force_near(&self, p: usize, mass: f64, x: &Vec3, v: &Vec3, near: Near) -> Vec3 {
        let mut f = self.gravity * mass;
        if let Some(field) = &self.field {
            f += field.sample(x);
        }
        if self.drag != 0.0 {
            f -= v * self.drag;
        }
        let mut margin = None;
        for (k, slot) in self.colliders.iter().enumerate() {
            if slot.response.is_force() && near.may_touch(k) {
                let m = *margin.get_or_insert_with(|| self.margin(p));
                slot.shape.contacts_within(x, m, &mut |c: Contact| {
                    f += slot.response.penalty_force(&c, v)
                });
            }
        }
        f
    }

    /// The force of the attachments holding particle `p`.
    #[inline]
    pub fn attachment_force(&self, p: usize, x: &Vec3, v: &Vec3) -> Vec3 {
        let mut f = Vec3::zeros();
        for a in self.attachments.iter().filter(|a| a.particle == p) {
            f -= (x - a.target) * a.ks + v * a.kd;
        }
        f
    }

    /// Applies the velocity-level responses (restitution, stick) after a full step. `x0` are
    /// the positions at the start of the step, for the crossing test of thin colliders.
    ///
    /// `stuck` records, per particle, whether it is held by a stick response: set when one
    /// resolved it this step, kept while it has not moved since (the implicit integrator
    /// holds stuck particles in place, so they are not re-detected). Explicit integrators
    /// ignore it.
    ///
    /// `margin[p]` is particle `p`'s contact thickness (an empty slice: zero for all): the
    /// responses put it that far out of the surface.
    ///
    /// `skips` (one per particle) lets a particle skip the colliders it provably cannot
    /// touch (see [`FaceSkip`]; [`FaceSkip::NEVER`] checks them all): the same results, bit
    /// for bit.
    ///
    /// Returns whether any response ran (the model has velocity-level colliders).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn resolve_contacts(
        &self,
        inv_mass: &[f64],
        margin: &[f64],
        x0: &[Vec3],
        x: &mut [Vec3],
        v: &mut [Vec3],
        stuck: &mut [bool],
        skips: &mut [FaceSkip],
    ) -> bool {
        if !self.has_contact_responses() {
            return false;
        }
        let resolve = |start: usize,
                       x: &mut [Vec3],
                       v: &mut [Vec3],
                       stuck: &mut [bool],
                       skips: &mut [FaceSkip]| {
            for k in 0..x.len() {
                let p = start + k;
                let m = margin.get(p).copied().unwrap_or(0.0);
                let (x, v) = (&mut x[k], &mut v[k]);
                let skip = Some(&mut skips[k]).filter(|s| s.enabled);
                stuck[k] = self.resolve_particle(inv_mass[p], m, &x0[p], x, v, stuck[k], skip);
            }
        };
        // Mesh queries cost microseconds each, so even small blocks are worth sharing.
        parallel::for_blocks4(CONTACT_BLOCK, x, v, stuck, skips, resolve);
        true
    }

    /// The velocity-level responses for one particle with inverse mass `inv_mass` and
    /// contact thickness `margin`, which started the step at `x0`; `stuck` is whether a stick
    /// response held it before. Returns whether one holds it now. With `skip`, the colliders
    /// it shows the particle cannot touch are skipped, and `skip` is kept up to date.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn resolve_particle(
        &self,
        inv_mass: f64,
        margin: f64,
        x0: &Vec3,
        x: &mut Vec3,
        v: &mut Vec3,
        stuck: bool,
        mut skip: Option<&mut FaceSkip>,
    ) -> bool {
        if inv_mass == 0.0 {
            return stuck;
        }
        let integrated = *x;
        if let Some(skip) = skip.as_deref_mut() {
            if skip.last.x.is_nan() {
                skip.last = *x0;
            }
            skip.path += (x0 - skip.last).norm() + (integrated - x0).norm();
            skip.last = integrated;
        }
        let mut held = stuck && *x == *x0;
        for (c, slot) in self
            .colliders
            .iter()
            .filter(|c| !c.response.is_force())
            .enumerate()
        {
            let tracked = c < FACE_SKIP_COLLIDERS;
            if tracked && skip.as_ref().is_some_and(|s| s.path < s.budget[c]) {
                continue;
            }
            let here = *x;
            let mut touched = false;
            let mut apply = |c: Contact| {
                touched = true;
                slot.response.resolve(&c, x, v);
            };
            // With no margin this is `contacts`, the Collider contract says.
            slot.shape.contacts_within(&here, margin, &mut apply);
            if !touched && let Some(mut c) = slot.shape.crossing(x0, &here) {
                touched = true;
                c.depth += margin;
                slot.response.resolve(&c, x, v);
            }
            held |= touched && matches!(slot.response, Response::Stick);
            if let Some(skip) = skip.as_deref_mut()
                && tracked
            {
                skip.budget[c] = if touched {
                    f64::NEG_INFINITY
                } else {
                    skip.clearance(slot.shape.as_ref(), &here, &integrated, margin)
                };
            }
        }
        held
    }

    /// Total potential energy in joules: springs, gravity (zero at the origin) and penalty
    /// springs. The force field has no potential in general and is left out.
    pub fn potential_energy(&self, mass: &[f64], x: &[Vec3]) -> f64 {
        let springs: f64 = self
            .springs
            .iter()
            .map(|s| s.energy(&x[s.i as usize], &x[s.j as usize]))
            .sum();
        let gravity: f64 = x
            .iter()
            .zip(mass)
            .map(|(x, m)| -m * self.gravity.dot(x))
            .sum();
        let mut penalty = 0.0;
        for slot in &self.colliders {
            if let Response::Penalty { kc, .. } = slot.response {
                for p in x {
                    slot.shape
                        .contacts(p, &mut |c| penalty += 0.5 * kc * c.depth * c.depth);
                }
            }
        }
        springs + gravity + penalty
    }

    /// The deepest penetration of any particle into any collider, in metres.
    pub fn max_penetration(&self, x: &[Vec3]) -> f64 {
        self.colliders
            .iter()
            .flat_map(|slot| x.iter().map(|p| slot.shape.depth(p)))
            .fold(0.0, f64::max)
    }
}
