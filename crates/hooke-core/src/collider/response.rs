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
    /// `-cr (v·n)`; the tangential velocity is scaled by `1 - friction`.
    Restitution {
        /// Coefficient of restitution in `[0, 1]`.
        cr: f64,
        /// Fraction of tangential velocity removed at each contact, in `[0, 1]` (0 keeps it).
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

    /// Applies a velocity-level response for one contact to a particle, in place.
    ///
    /// The particle moves by `δ n` rather than to `contact.point` so that several contacts of
    /// one collider (the faces at a box corner) compose into the nearest point of all of them.
    pub fn respond(&self, contact: &Contact, x: &mut Vec3, v: &mut Vec3) {
        match *self {
            Self::Penalty { .. } => {}
            Self::Restitution { cr, friction } => {
                *x += contact.normal * contact.depth;
                let vn = v.dot(&contact.normal);
                if vn < 0.0 {
                    let tangential = (*v - contact.normal * vn) * (1.0 - friction);
                    *v = tangential + contact.normal * (-cr * vn);
                }
            }
            Self::Stick => {
                *x += contact.normal * contact.depth;
                *v = Vec3::zeros();
            }
        }
    }
}
