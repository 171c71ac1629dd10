//! A collider that follows keys (docs/physics.md §2.1): any still shape, answered in its own
//! frame. A query at `p` maps `p` into the shape's frame at the step's end, asks the shape,
//! and maps the answer back; a step's crossing test maps its start through the pose at the
//! step's start and its end through the pose at the end, so the shape sees the particle's
//! path relative to itself.

use crate::collider::{Circle, Collider, Contact, Feature};
use crate::keyframes::Keyframes;
use crate::particles::Vec3;
use nalgebra::Rotation3;

/// Parts at least each pair of keys is cut into for [`Collider::motion_spans`], so that
/// the sweep of each is near the motion's length along a curved path.
const SPANS_PER_KEY: usize = 32;

/// A rigid pose: `x ↦ pivot + translate + rotation (x - pivot)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pose {
    rotation: Rotation3<f64>,
    translate: Vec3,
}

impl Pose {
    fn world_of(&self, pivot: &Vec3, q: &Vec3) -> Vec3 {
        pivot + self.translate + self.rotation * (q - pivot)
    }

    fn shape_of(&self, pivot: &Vec3, p: &Vec3) -> Vec3 {
        pivot + self.rotation.inverse() * (p - pivot - self.translate)
    }
}

/// The eight corners of the box `lo..hi`.
fn corners(lo: &Vec3, hi: &Vec3) -> [Vec3; 8] {
    std::array::from_fn(|k| {
        Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// A shape moved by keys about `pivot` (its placed origin or centre).
#[derive(Debug)]
pub struct Moving {
    shape: Box<dyn Collider>,
    pivot: Vec3,
    keys: Keyframes,
    /// Poses at the step's start and end, and the step's length.
    before: Pose,
    now: Pose,
    dt: f64,
}

impl Moving {
    /// `shape` (as placed in the scene) moved by `keys` about `pivot`, at time 0.
    pub fn new(shape: Box<dyn Collider>, pivot: Vec3, keys: Keyframes) -> Self {
        let start = Self::pose(&keys, 0.0);
        Self {
            shape,
            pivot,
            keys,
            before: start,
            now: start,
            dt: 0.0,
        }
    }

    fn pose(keys: &Keyframes, t: f64) -> Pose {
        let (rotation, translate) = keys.pose(t);
        Pose {
            rotation,
            translate,
        }
    }

    /// The keys it follows.
    pub fn keys(&self) -> &Keyframes {
        &self.keys
    }

    /// The point it turns about.
    pub fn pivot(&self) -> Vec3 {
        self.pivot
    }

    fn world(&self, q: &Vec3) -> Vec3 {
        self.now.world_of(&self.pivot, q)
    }

    fn local(&self, p: &Vec3) -> Vec3 {
        self.now.shape_of(&self.pivot, p)
    }

    fn contact(&self, c: Contact) -> Contact {
        Contact {
            depth: c.depth,
            normal: self.now.rotation * c.normal,
            point: self.world(&c.point),
        }
    }

    /// The shape-frame box holding the world box `lo..hi` (its corners mapped, widened by
    /// a rounding margin so that a promise of no contact stays a promise).
    fn local_box(&self, lo: &Vec3, hi: &Vec3) -> (Vec3, Vec3) {
        let mut a = Vec3::repeat(f64::INFINITY);
        let mut b = Vec3::repeat(f64::NEG_INFINITY);
        for corner in corners(lo, hi) {
            let q = self.local(&corner);
            a = a.inf(&q);
            b = b.sup(&q);
        }
        let slack = 1e-9 * (1.0 + a.amax().max(b.amax()));
        (a.add_scalar(-slack), b.add_scalar(slack))
    }
}

impl Collider for Moving {
    fn name(&self) -> String {
        format!("moving {}", self.shape.name())
    }

    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
        self.shape
            .contacts(&self.local(p), &mut |c| sink(self.contact(c)));
    }

    fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
        self.shape
            .contacts_within(&self.local(p), margin, &mut |c| sink(self.contact(c)));
    }

    fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
        if lo.iter().chain(hi.iter()).any(|c| c.is_nan()) {
            return true;
        }
        let (a, b) = self.local_box(lo, hi);
        self.shape.may_touch(&a, &b, margin)
    }

    fn features(&self, lo: &Vec3, hi: &Vec3, sink: &mut dyn FnMut(Feature)) {
        let (a, b) = self.local_box(lo, hi);
        self.shape.features(&a, &b, &mut |f| {
            sink(match f {
                Feature::Segment([p, q]) => Feature::Segment([self.world(&p), self.world(&q)]),
                Feature::Circle(c) => Feature::Circle(Circle {
                    center: self.world(&c.center),
                    axis: self.now.rotation * c.axis,
                    radius: c.radius,
                }),
                Feature::Ball { center, radius } => Feature::Ball {
                    center: self.world(&center),
                    radius,
                },
            })
        });
    }

    fn has_features(&self) -> bool {
        self.shape.has_features()
    }

    fn crossing(&self, from: &Vec3, to: &Vec3) -> Option<Contact> {
        let from = self.before.shape_of(&self.pivot, from);
        self.shape
            .crossing(&from, &self.local(to))
            .map(|c| self.contact(c))
    }

    fn thickness(&self) -> Option<f64> {
        self.shape.thickness()
    }

    fn segment_meets(&self, a: &Vec3, b: &Vec3) -> bool {
        self.shape.segment_meets(&self.local(a), &self.local(b))
    }

    fn advance_to(&mut self, t0: f64, t1: f64) {
        self.before = Self::pose(&self.keys, t0);
        self.now = Self::pose(&self.keys, t1);
        self.dt = t1 - t0;
    }

    fn is_moving(&self) -> bool {
        true
    }

    fn motion_spans(&self) -> Vec<(f64, f64)> {
        let mut spans = Vec::new();
        for pair in self.keys.keys().windows(2) {
            let (ta, tb) = (pair[0].t, pair[1].t);
            // A sweep has no bound for a turn of 60° or more: a spinning collider's span is
            // cut until each part turns at most 30° about every axis.
            let turn = (pair[1].rotate - pair[0].rotate).abs().max();
            let parts = SPANS_PER_KEY.max((turn / 30.0).ceil().min(1e6) as usize);
            let step = (tb - ta) / parts as f64;
            spans.extend((0..parts).map(|k| {
                let t = ta + step * k as f64;
                (t, t + step)
            }));
        }
        spans
    }

    fn sweep(&self, (t0, t1): (f64, f64), lo: &Vec3, hi: &Vec3) -> f64 {
        // A point at `pivot + T₀ + R₀ q` goes to `pivot + T₁ + R₁ q`: it moves
        // `d ≤ |T₁ - T₀| + k |R₀ q|`, with `k = ‖R₁ R₀ᵀ - I‖ = 2 sin(θ/2)` for a turn by θ.
        // A point that ends up, or passes, within `d` of a point of the box started within
        // `d` of it, so `|R₀ q| ≤ r + d` with `r` the box's farthest corner from
        // `pivot + T₀` (a convex function's maximum): `d ≤ (|ΔT| + k r) / (1 - k)`, finite
        // for turns under 60°.
        let (a, b) = (Self::pose(&self.keys, t0), Self::pose(&self.keys, t1));
        let k = 2.0 * (0.5 * (b.rotation * a.rotation.inverse()).angle()).sin();
        if k >= 1.0 {
            return f64::INFINITY;
        }
        let reach = corners(lo, hi)
            .iter()
            .map(|c| (c - self.pivot - a.translate).norm())
            .fold(0.0, f64::max);
        ((b.translate - a.translate).norm() + k * reach) / (1.0 - k)
    }

    fn velocity(&self, p: &Vec3) -> Vec3 {
        if self.dt <= 0.0 {
            return Vec3::zeros();
        }
        let was = self.before.world_of(&self.pivot, &self.local(p));
        (p - was) / self.dt
    }

    fn carried(&self, p: &Vec3) -> Vec3 {
        self.world(&self.before.shape_of(&self.pivot, p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::keyframes::Key;

    /// A shape with no surface: only the pose matters here.
    #[derive(Debug)]
    struct Nothing;

    impl Collider for Nothing {
        fn name(&self) -> String {
            "nothing".into()
        }
        fn contacts(&self, _: &Vec3, _: &mut dyn FnMut(Contact)) {}
    }

    /// Keys turning `degrees` about y while moving 0.3 m along x, from 0 s to 1 s, about
    /// a pivot at (1, 0, 0).
    fn turning(degrees: f64) -> Moving {
        let key = |t: f64, x: f64, ry: f64| Key {
            t,
            translate: Vec3::new(x, 0.0, 0.0),
            rotate: Vec3::new(0.0, ry, 0.0),
        };
        let keys = Keyframes::new(vec![key(0.0, 0.0, 0.0), key(1.0, 0.3, degrees)]).unwrap();
        Moving::new(Box::new(Nothing), Vec3::new(1.0, 0.0, 0.0), keys)
    }

    /// Every material point that starts or ends in the box moves no farther than the sweep
    /// says, for turns up to 50°; at 60° and more there is no bound.
    #[test]
    fn the_sweep_bounds_every_point_that_meets_the_box() {
        let (lo, hi) = (Vec3::new(-0.5, -0.2, -0.5), Vec3::new(0.5, 0.2, 0.5));
        let inside = |p: &Vec3| (0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k]);
        for degrees in [0.0, 5.0, 20.0, 50.0] {
            let m = turning(degrees);
            let s = m.sweep((0.0, 1.0), &lo, &hi);
            let (a, b) = (Moving::pose(&m.keys, 0.0), Moving::pose(&m.keys, 1.0));
            let mut met = 0;
            for i in 0..41 {
                for j in 0..41 {
                    // Shape-frame points over a 4 m square about the pivot.
                    let q = Vec3::new(-1.0 + 0.1 * i as f64, 0.1, -2.0 + 0.1 * j as f64);
                    let (from, to) = (a.world_of(&m.pivot, &q), b.world_of(&m.pivot, &q));
                    if inside(&from) || inside(&to) {
                        met += 1;
                        let d = (to - from).norm();
                        assert!(d <= s * (1.0 + 1e-12), "{degrees}°: {d} > {s}");
                    }
                }
            }
            assert!(met > 50, "{degrees}°: only {met} points met the box");
        }
        assert_eq!(turning(60.0).sweep((0.0, 1.0), &lo, &hi), f64::INFINITY);
        assert_eq!(turning(0.0).sweep((0.0, 1.0), &lo, &hi), 0.3);
    }
}
