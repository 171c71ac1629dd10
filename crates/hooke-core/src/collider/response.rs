//! Collision responses (docs/physics.md §3.3): what happens to a particle a collider reports.

use crate::collider::Contact;
use crate::particles::Vec3;

/// How a collider acts on the particles that violate it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Response {
    /// A zero-rest-length spring pushing out, `kc δ n - dc (v·n) n`, evaluated inside every
    /// force evaluation (so inside every RK stage).
    Penalty {
        /// Stiffness in N/m.
        kc: f64,
        /// Damping in N·s/m.
        dc: f64,
    },
    /// After each full step: moved to the surface; an inward normal velocity `v·n < 0` becomes
    /// `-cr (v·n)`, and Coulomb friction takes at most `friction` times that normal impulse
    /// off the tangential velocity (docs/physics.md §3.3).
    Restitution {
        /// Coefficient of restitution in `[0, 1]`.
        cr: f64,
        /// Coulomb's coefficient of friction μ ≥ 0 (0: frictionless).
        friction: f64,
    },
    /// After each full step: moved to the surface and stopped (the tabletop rule).
    Stick,
}

impl Response {
    /// Whether this response acts through forces (inside the integrator) rather than after it.
    pub fn is_force(&self) -> bool {
        matches!(self, Self::Penalty { .. })
    }

    /// The penalty force for one contact (zero for velocity-level responses).
    #[inline]
    pub fn penalty_force(&self, contact: &Contact, v: &Vec3) -> Vec3 {
        match *self {
            Self::Penalty { kc, dc } => {
                let n = contact.normal;
                n * (kc * contact.depth) - n * (dc * v.dot(&n))
            }
            _ => Vec3::zeros(),
        }
    }

    /// Applies a velocity-level response for one contact to a particle, in place. `start` is
    /// where the particle started the step, carried along by the collider, and `u` the
    /// collider's velocity at the contact ([`crate::Collider::carried`],
    /// [`crate::Collider::velocity`]: `x0` and zero for a still collider): the response acts
    /// on the velocity and the step's motion relative to the collider.
    ///
    /// The particle moves by `δ n` rather than to `contact.point` so that several contacts of
    /// one collider (the faces at a box corner) compose into the nearest point of all of them.
    /// Friction acts within the step: the share of the tangential velocity it takes off is
    /// also taken off the step's tangential displacement, so a contact that sticks does not
    /// creep by the one step's slide that came before the response.
    pub fn respond(
        &self,
        contact: &Contact,
        (start, u): (&Vec3, &Vec3),
        x: &mut Vec3,
        v: &mut Vec3,
    ) {
        match *self {
            Self::Penalty { .. } => {}
            Self::Restitution { cr, friction } => {
                let n = contact.normal;
                *x += n * contact.depth;
                let relative = *v - u;
                let vn = relative.dot(&n);
                if vn < 0.0 {
                    let tangential = relative - n * vn;
                    let cut = coulomb_cut(friction, -(1.0 + cr) * vn, &tangential);
                    *v = tangential - tangential * cut + n * (-cr * vn);
                    // Added only for a moving collider: `-0 + 0` would flip a sign bit.
                    if *u != Vec3::zeros() {
                        *v += u;
                    }
                    if cut > 0.0 {
                        let moved = *x - start;
                        *x -= (moved - n * n.dot(&moved)) * cut;
                    }
                }
            }
            Self::Stick => {
                *x += contact.normal * contact.depth;
                *v = *u;
            }
        }
    }
}

/// The share of the tangential velocity `tangential` that Coulomb friction with coefficient
/// `mu` takes off after a normal velocity change `dvn ≥ 0`: at most `mu dvn`, all of it when
/// that is enough (the contact sticks). The same law in every integrator (a velocity change
/// is an impulse over the mass), so a sliding contact decelerates at `mu` times its normal
/// acceleration whatever the step.
#[inline]
pub(crate) fn coulomb_cut(mu: f64, dvn: f64, tangential: &Vec3) -> f64 {
    let t = tangential.norm();
    if t > COULOMB_EPS {
        (mu * dvn / t).min(1.0)
    } else {
        0.0
    }
}

/// Tangential speeds below this have no direction to oppose, m/s.
const COULOMB_EPS: f64 = 1e-12;
