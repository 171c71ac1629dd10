//! The `Collider` trait the core owns; concrete shapes live in `hooke-collide`.

use crate::particles::Vec3;
use std::fmt::Debug;

/// One violated surface: how deep a point is, which way is out, and where out is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Penetration depth `δ > 0` in metres.
    pub depth: f64,
    /// Unit normal pointing out of the collider at the nearest surface point.
    pub normal: Vec3,
    /// The nearest surface point, in metres.
    pub point: Vec3,
}

/// A solid (or thin) obstacle that particles must stay out of (SPEC §2).
///
/// Implementors answer point queries; the responses (penalty, restitution, stick) are the
/// core's, so a collider never touches velocities.
pub trait Collider: Debug + Send + Sync {
    /// A short name for messages, e.g. `ground` or `mesh table.obj`.
    fn name(&self) -> String;

    /// Calls `sink` once for every violated surface at `p` (a box can report up to three
    /// faces; most shapes report zero or one).
    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact));

    /// For thin or open shapes: if the straight path `from → to` of one step crosses the
    /// surface although `to` is not inside, the surface point where it crossed, with the normal
    /// facing `from`. Closed shapes that only answer inside tests keep the default (`None`).
    fn crossing(&self, from: &Vec3, to: &Vec3) -> Option<Contact> {
        let _ = (from, to);
        None
    }

    /// The thinnest extent of the solid in metres, for the tunnelling check: a particle that
    /// moves more than half of it in one step can end nearer the far side and be pushed out
    /// there. `None` for half-spaces and for open sheets (which the crossing test guards).
    fn thickness(&self) -> Option<f64> {
        None
    }

    /// Whether `p` is inside.
    fn inside(&self, p: &Vec3) -> bool {
        let mut any = false;
        self.contacts(p, &mut |_| any = true);
        any
    }

    /// The deepest penetration at `p` (zero outside).
    fn depth(&self, p: &Vec3) -> f64 {
        let mut deepest = 0.0_f64;
        self.contacts(p, &mut |c| deepest = deepest.max(c.depth));
        deepest
    }
}
