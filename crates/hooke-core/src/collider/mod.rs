//! The `Collider` trait the core owns; concrete shapes live in `hooke-collide`.

pub(crate) mod moving;
pub(crate) mod response;

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

/// A sharp part of a collider's surface that a cloth face can touch between its particles:
/// an edge where two faces meet at an angle, the rim of a disc. Faces are covered by the
/// per-particle contacts; features are what pokes through a cloth triangle whose corners are
/// all outside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Feature {
    /// A straight edge between two points (a mesh edge, a corner where it ends).
    Segment([Vec3; 2]),
    /// A circular edge (the analytic cylinder's rims).
    Circle(Circle),
    /// A smooth ball's surface, seen from a triangle as its point nearest the triangle: a
    /// cloth triangle whose corners keep their distance from a ball can still dip into it
    /// between them when its edges are long against the radius (deeper than `l²/(8R)`).
    Ball {
        /// Centre, metres.
        center: Vec3,
        /// Radius, metres.
        radius: f64,
    },
}

impl Feature {
    /// The feature's bounding box `(lo, hi)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match self {
            Self::Segment([a, b]) => (a.inf(b), a.sup(b)),
            Self::Circle(c) => {
                // Per axis, a circle extends r·√(1 - axis²) from its centre.
                let e = c.axis.map(|a| c.radius * (1.0 - a * a).max(0.0).sqrt());
                (c.center - e, c.center + e)
            }
            Self::Ball { center, radius } => {
                (center.add_scalar(-radius), center.add_scalar(*radius))
            }
        }
    }
}

/// A solid (or thin) obstacle that particles must stay out of (docs/physics.md §2).
///
/// Implementors answer point queries; the responses (penalty, restitution, stick) are the
/// core's, so a collider never touches velocities.
pub trait Collider: Debug + Send + Sync {
    /// A short name for messages, e.g. `ground` or `mesh table.obj`.
    fn name(&self) -> String;

    /// Calls `sink` once for every violated surface at `p` (a box can report up to three
    /// faces; most shapes report zero or one).
    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact));

    /// [`Collider::contacts`] for a particle that keeps `margin` metres from the surface (a
    /// body's contact thickness): also reports points outside but nearer than `margin`, with
    /// `depth = margin - distance` (so moving by `depth · normal` puts the point `margin` out)
    /// and `point` the nearest surface point. With `margin == 0` this is exactly `contacts`,
    /// which the default always calls: shapes that support a margin override it.
    fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
        self.contacts(p, &mut |mut c| {
            c.depth += margin;
            sink(c);
        });
    }

    /// Whether some point of the box `lo..hi` may have a contact within `margin` (with
    /// [`Collider::contacts_within`], or [`Collider::contacts`] for a zero margin, at any
    /// margin up to `margin`), or a segment within the box a [`Collider::crossing`].
    /// `false` promises that no point of the box has one and no such segment crosses, so
    /// callers may skip asking for every particle in it; the default never promises.
    /// Shapes that answer must do so in the same arithmetic as their contact tests, so that
    /// the promise holds to the last bit, and must answer `true` for a box with NaN bounds.
    fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
        let _ = (lo, hi, margin);
        true
    }

    /// Calls `sink` with every sharp [`Feature`] of the surface that may lie in the box
    /// `lo..hi` (more is allowed, fewer is not). Smooth shapes (planes, the box interior,
    /// whose edges are concave from the free side) have none, the default.
    fn features(&self, lo: &Vec3, hi: &Vec3, sink: &mut dyn FnMut(Feature)) {
        let _ = (lo, hi, sink);
    }

    /// Whether [`Collider::features`] can report anything, so callers may skip asking.
    fn has_features(&self) -> bool {
        false
    }

    /// For thin or open shapes: if the straight path `from → to` of one step crosses the
    /// surface although `to` is not inside, the surface point where it crossed, with the normal
    /// facing `from`. Closed shapes that only answer inside tests keep the default (`None`).
    fn crossing(&self, from: &Vec3, to: &Vec3) -> Option<Contact> {
        let _ = (from, to);
        None
    }

    /// Whether the straight segment `a → b` (a spring, a cloth edge) meets the solid: an end
    /// inside it, or its inside (or a thin or open surface) between the ends. This is what
    /// "a surface passes through a collider" means for the start's push-out and the
    /// crossing watch (docs/physics.md §3.4, §3.5). The default asks the ends and the
    /// crossing test both ways, which is exact for shapes whose free side is convex (planes,
    /// the box interior) and for meshes; round solids answer exactly themselves.
    fn segment_meets(&self, a: &Vec3, b: &Vec3) -> bool {
        self.inside(a)
            || self.inside(b)
            || self.crossing(a, b).is_some()
            || self.crossing(b, a).is_some()
    }

    /// Whether the solid is exactly a half-space: every point on the free side of its
    /// surface's tangent plane anywhere is outside (an infinite plane). Block descent then
    /// bounds only the motion that closes a particle's gap to it, not its sliding along it
    /// (docs/physics.md §4.1). The default, `false`, is always safe.
    fn is_half_space(&self) -> bool {
        false
    }

    /// The thinnest extent of the solid in metres, for the tunnelling check: a particle that
    /// moves more than half of it in one step can end nearer the far side and be pushed out
    /// there. `None` for half-spaces and for open sheets (which the crossing test guards).
    fn thickness(&self) -> Option<f64> {
        None
    }

    /// Takes the collider's pose for a step from `t0` to `t1` (seconds): queries answer at
    /// `t1`, and [`Collider::velocity`] and [`Collider::carried`] over the step. Still
    /// colliders ignore it, the default.
    fn advance_to(&mut self, t0: f64, t1: f64) {
        let _ = (t0, t1);
    }

    /// Whether the collider moves (then callers may not cache what it answered).
    fn is_moving(&self) -> bool {
        false
    }

    /// The spans of time `(t0, t1)` over which the collider moves, each short enough for
    /// [`Collider::sweep`] to bound it (a keyed turn cut into parts of at most 30°); none
    /// for a still collider. The energy watch sums its allowance for the collider's work
    /// over them.
    fn motion_spans(&self) -> Vec<(f64, f64)> {
        Vec::new()
    }

    /// How far at most a material point of the collider moves from time `t0` to `t1`, of
    /// the points that start, end or pass as near a point of the world box `lo..hi` as
    /// they move (zero for a still collider; infinite when no bound is known, as for a
    /// turn of 60° or more). Pure: it does not take the pose, so a caller can try several
    /// spans before [`Collider::advance_to`].
    fn sweep(&self, (t0, t1): (f64, f64), lo: &Vec3, hi: &Vec3) -> f64 {
        let _ = (t0, t1, lo, hi);
        0.0
    }

    /// The velocity over the current step of the collider's material point now at `p`
    /// (zero for a still collider).
    fn velocity(&self, p: &Vec3) -> Vec3 {
        let _ = p;
        Vec3::zeros()
    }

    /// Where the collider's material point that was at `p` at the step's start is at its
    /// end (`p` itself for a still collider).
    fn carried(&self, p: &Vec3) -> Vec3 {
        *p
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

/// A circle in space: the rim of a round tabletop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Centre, metres.
    pub center: Vec3,
    /// Unit normal of the circle's plane.
    pub axis: Vec3,
    /// Radius, metres.
    pub radius: f64,
}
