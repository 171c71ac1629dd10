//! The force model of a system: everything that is constant during a run.

pub(crate) mod motion;
pub(crate) mod surface;

use crate::collider::response::Response;
use crate::collider::{Collider, Contact};
use crate::forces::air::{AeroSurface, Air};
use crate::forces::field::ForceField;
use crate::forces::spring::Spring;
use crate::model::motion::PinMotion;
use crate::model::surface::Surface;
use crate::particles::Vec3;

/// A collider together with the response it triggers.
#[derive(Debug)]
pub struct ColliderSlot {
    /// The shape.
    pub shape: Box<dyn Collider>,
    /// What it does to particles that violate it.
    pub response: Response,
}

/// The most contact thickness a point keeps from a collider under the large steps, metres
/// ([`Model::point_thickness`]).
pub(crate) const POINT_THICKNESS: f64 = 1e-3;

/// How far, in its thicknesses, the large steps skip a surface's contacts with itself
/// ([`Model::self_contact_skip`]): block descent's search reach between surfaces, so that
/// no neighbour of a flat or gently curved sheet bounds its particles. Farther (eight
/// thicknesses) let the shipped curtain's 5 cm quads fold through each other.
pub(crate) const SELF_CONTACT_SKIP: f64 = 4.0;

/// Springs, external forces and colliders, and the per-particle masses they act on.
///
/// Forces are evaluated per docs/physics.md §1 by the spring assembly (`assembly/`), which sums them in an order
/// fixed by the problem, so results are the same bits however the work is split.
#[derive(Debug, Default)]
pub struct Model {
    /// Every spring of the system.
    pub springs: Vec<Spring>,
    /// Gravitational acceleration in m/s², applied as the force `m g`.
    pub gravity: Vec3,
    /// Linear drag in N·s/m per particle (force `-drag v` on every particle, the course's
    /// convention); zero disables it.
    pub drag: f64,
    /// Linear drag in N·s/m per kilogram (force `-mass_drag m v`): the same for a body at
    /// any resolution; zero disables it.
    pub mass_drag: f64,
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
    /// Pinned particles that follow keys (docs/physics.md §1.2).
    pub pin_motions: Vec<PinMotion>,
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
pub(crate) struct Near(u64);

impl Near {
    /// Every collider may touch.
    pub(crate) const ALL: Self = Self(u64::MAX);

    /// Whether collider `k` may touch.
    #[inline]
    pub(crate) fn may_touch(self, k: usize) -> bool {
        k >= 64 || self.0 >> k & 1 == 1
    }
}

impl Model {
    /// Whether gravity is the only force besides the springs (no field, drag, air, penalty
    /// colliders or attachments): integrators then use a loop without the per-particle
    /// tests of [`Model::external_force`], whose result it equals to the bit.
    pub fn gravity_only(&self) -> bool {
        self.field.is_none()
            && !self.has_drag()
            && self.air.is_none()
            && self.attachments.is_empty()
            && self.colliders.iter().all(|c| !c.response.is_force())
    }

    /// Whether any drag acts.
    pub fn has_drag(&self) -> bool {
        self.drag != 0.0 || self.mass_drag != 0.0
    }

    /// The drag coefficient on a particle of `mass` kg, N·s/m: `drag + mass_drag · mass`.
    #[inline]
    pub fn drag_on(&self, mass: f64) -> f64 {
        self.drag + self.mass_drag * mass
    }

    /// Whether any collider has a velocity-level response (restitution, stick), which
    /// `contact::respond::respond_all` applies after each step from the step's start positions.
    pub fn has_contact_responses(&self) -> bool {
        self.colliders.iter().any(|c| !c.response.is_force())
    }

    /// Whether the contact phase after each step has work: velocity-level responses or
    /// surfaces with a thickness. It reads the step's start positions.
    pub fn has_contact_phase(&self) -> bool {
        self.has_contact_responses() || self.surfaces.iter().any(Surface::is_active)
    }

    /// Whether any collider moves by keys.
    pub(crate) fn has_moving_colliders(&self) -> bool {
        self.colliders.iter().any(|c| c.shape.is_moving())
    }

    /// The surfaces with a thickness (whose contacts are on), with their indices.
    pub(crate) fn active_surfaces(&self) -> impl Iterator<Item = (usize, &Surface)> {
        self.surfaces
            .iter()
            .enumerate()
            .filter(|(_, s)| s.is_active())
    }

    /// Whether any pair of active surfaces can touch: two of them, or one that collides
    /// with itself.
    pub(crate) fn surfaces_touch(&self) -> bool {
        let mut active = self.active_surfaces();
        match (active.next(), active.next()) {
            (Some(_), Some(_)) => true,
            (Some((_, s)), None) => s.self_collision,
            _ => false,
        }
    }

    /// The contact thickness the large steps (`vbd`, `newton`) keep between a particle
    /// outside every active surface (a chain's, a lattice's, a point's) and a restitution or
    /// stick collider, metres: 1 mm, or a quarter of the model's shortest
    /// spring when that is less, so that a small body's neighbours are not thicknesses
    /// apart. With none, the bounds of docs/physics.md §4.1 let such a particle approach a
    /// collider by nine tenths of its gap per detection until rounding put it inside, where
    /// nothing bounds it.
    pub fn point_thickness(&self) -> f64 {
        let shortest = self
            .springs
            .iter()
            .map(|s| s.rest)
            .filter(|&r| r > 0.0)
            .fold(f64::INFINITY, f64::min);
        POINT_THICKNESS.min(0.25 * shortest)
    }

    /// The distance along a surface within which the large steps (`vbd`, `newton`) skip
    /// its contacts with itself, metres: `SELF_CONTACT_SKIP` times the largest thickness of
    /// the surfaces whose contacts are on (zero without one), four thicknesses. A particle and a triangle, or
    /// two edges, of one surface that lie within it of each other in the rest shape, joined
    /// through the surface's own triangles within it, are held apart by the surface's own
    /// springs and never measured (docs/physics.md §4.1, "What self-contact skips"); a
    /// crease that brings such a pair within a thickness can cross.
    pub fn self_contact_skip(&self) -> f64 {
        let h = self
            .active_surfaces()
            .map(|(_, s)| s.thickness)
            .fold(0.0, f64::max);
        SELF_CONTACT_SKIP * h
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
    pub(crate) fn total_force_near(
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
    pub(crate) fn near(&self, x: &[Vec3]) -> Near {
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
    pub(crate) fn gravity_only_near(&self, near: Near) -> bool {
        self.field.is_none()
            && !self.has_drag()
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
    pub(crate) fn external_force_near(
        &self,
        p: usize,
        mass: f64,
        x: &Vec3,
        v: &Vec3,
        near: Near,
    ) -> Vec3 {
        let mut f = self.gravity * mass;
        if let Some(field) = &self.field {
            f += field.sample(x);
        }
        if self.has_drag() {
            f -= v * self.drag_on(mass);
        }
        let mut margin = None;
        for (k, slot) in self.colliders.iter().enumerate() {
            if slot.response.is_force() && near.may_touch(k) {
                let m = *margin.get_or_insert_with(|| self.margin(p));
                slot.shape.contacts_within(x, m, &mut |c: Contact| {
                    // Damping acts on the velocity relative to a moving collider.
                    if slot.shape.is_moving() {
                        f += slot
                            .response
                            .penalty_force(&c, &(v - slot.shape.velocity(&c.point)))
                    } else {
                        f += slot.response.penalty_force(&c, v)
                    }
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
