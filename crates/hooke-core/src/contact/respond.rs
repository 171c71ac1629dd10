//! The velocity-level responses of docs/physics.md §3.2 after each step (reflect with
//! restitution, stick), and the record that lets a particle skip colliders it provably
//! cannot touch.

use crate::collider::Collider;
use crate::collider::Contact;
use crate::collider::response::Response;
use crate::model::Model;
use crate::parallel;
use crate::particles::Vec3;

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
pub(crate) fn respond_all(
    model: &Model,
    inv_mass: &[f64],
    margin: &[f64],
    x0: &[Vec3],
    x: &mut [Vec3],
    v: &mut [Vec3],
    stuck: &mut [bool],
    skips: &mut [FaceSkip],
) -> bool {
    if !model.has_contact_responses() {
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
            stuck[k] = respond_one(model, inv_mass[p], m, &x0[p], x, v, stuck[k], skip);
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
pub(crate) fn respond_one(
    model: &Model,
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
    for (c, slot) in model
        .colliders
        .iter()
        .filter(|c| !c.response.is_force())
        .enumerate()
    {
        // A moving collider's clearance says nothing about the next step.
        let tracked = c < FACE_SKIP_COLLIDERS && !slot.shape.is_moving();
        if tracked && skip.as_ref().is_some_and(|s| s.path < s.budget[c]) {
            continue;
        }
        let here = *x;
        let mut touched = false;
        // A contact is answered relative to the collider: from the particle's start carried
        // along by it, at its velocity there (the start and zero for a still collider);
        // asked only when there is a contact, off the path of every particle that has none.
        let respond = |c: &Contact, x: &mut Vec3, v: &mut Vec3| {
            let (start, u) = (slot.shape.carried(x0), slot.shape.velocity(&c.point));
            slot.response.respond(c, (&start, &u), x, v);
        };
        let mut apply = |c: Contact| {
            touched = true;
            respond(&c, x, v);
        };
        // With no margin this is `contacts`, the Collider contract says.
        slot.shape.contacts_within(&here, margin, &mut apply);
        if !touched && let Some(mut c) = slot.shape.crossing(x0, &here) {
            touched = true;
            c.depth += margin;
            respond(&c, x, v);
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
