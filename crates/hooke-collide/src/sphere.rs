//! A solid ball: the analytic sphere collider.

use crate::bounds::{boxes_meet, touch_reach};
use hooke_core::{Collider, Contact, Feature, Vec3};

/// A solid ball of radius `R` about `C`: inside when `|p − C| < R`; the contact is with the
/// nearest surface point `C + R n`, `n = (p − C)/|p − C|` (straight up at the centre itself).
///
/// Smooth, yet a cloth triangle of edge `l` whose corners keep a thickness `h` from the ball
/// comes within `h − l²/(8R)` of it between them: a stretched cloth's edges dip into a small
/// ball. So the ball is also a feature ([`Feature::Ball`]): its point nearest each triangle
/// near it, kept a thickness from the triangle as a rim or an edge is.
///
/// ```
/// use hooke_collide::Sphere;
/// use hooke_core::{Collider, Vec3};
/// let ball = Sphere { center: Vec3::new(0.0, 1.0, 0.0), radius: 0.2 };
/// let mut hit = None;
/// ball.contacts(&Vec3::new(0.0, 1.15, 0.0), &mut |c| hit = Some(c));
/// let c = hit.unwrap();
/// assert_eq!(c.normal, Vec3::new(0.0, 1.0, 0.0));
/// assert!((c.depth - 0.05).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre `C`, metres.
    pub center: Vec3,
    /// Radius `R`, metres.
    pub radius: f64,
}

impl Sphere {
    /// The outward normal at `p`, and `p`'s distance from the centre.
    fn outward(&self, p: &Vec3) -> (Vec3, f64) {
        let d = p - self.center;
        let r = d.norm();
        (d.try_normalize(0.0).unwrap_or_else(Vec3::y), r)
    }
}

impl Collider for Sphere {
    fn name(&self) -> String {
        "sphere".to_string()
    }

    fn thickness(&self) -> Option<f64> {
        Some(2.0 * self.radius)
    }

    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
        self.contacts_within(p, 0.0, sink);
    }

    /// Within `R + margin` of the centre: depth `R + margin − |p − C|` along the radius.
    fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
        let (n, r) = self.outward(p);
        let reach = self.radius + margin;
        if r < reach {
            sink(Contact {
                depth: reach - r,
                normal: n,
                point: self.center + n * self.radius,
            });
        }
    }

    /// Whether the segment comes nearer the centre than the radius.
    fn segment_meets(&self, a: &Vec3, b: &Vec3) -> bool {
        let ab = b - a;
        let t = if ab.norm_squared() > 0.0 {
            ((self.center - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + ab * t - self.center).norm() < self.radius
    }

    /// The ball itself, when its box meets `lo..hi`.
    fn features(&self, lo: &Vec3, hi: &Vec3, sink: &mut dyn FnMut(Feature)) {
        let f = Feature::Ball {
            center: self.center,
            radius: self.radius,
        };
        let (a, b) = f.bounds();
        if (0..3).all(|k| a[k] <= hi[k] && lo[k] <= b[k]) {
            sink(f);
        }
    }

    fn has_features(&self) -> bool {
        true
    }

    /// Whether the box, grown by `margin` (and a little for rounding), meets the ball's
    /// bounding box.
    fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
        let (a, b) = (
            self.center.add_scalar(-self.radius),
            self.center.add_scalar(self.radius),
        );
        boxes_meet(lo, hi, &a, &b, touch_reach(lo, hi, margin))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BALL: Sphere = Sphere {
        center: Vec3::new(0.5, 1.0, -0.5),
        radius: 0.25,
    };

    /// A point at distance `d` from the centre along a diagonal.
    fn at(d: f64) -> Vec3 {
        BALL.center + Vec3::new(1.0, 2.0, -2.0) / 3.0 * d
    }

    #[test]
    fn inside_points_are_pushed_out_along_the_radius_to_the_surface() {
        let mut got = Vec::new();
        BALL.contacts(&at(0.2), &mut |c| got.push(c));
        assert_eq!(got.len(), 1);
        let c = got[0];
        assert!((c.depth - 0.05).abs() < 1e-12);
        assert!((c.normal - Vec3::new(1.0, 2.0, -2.0) / 3.0).norm() < 1e-12);
        assert!(((c.point - BALL.center).norm() - 0.25).abs() < 1e-12);
        // Moving by depth along the normal lands on the surface.
        assert!(((at(0.2) + c.normal * c.depth - BALL.center).norm() - 0.25).abs() < 1e-12);
    }

    #[test]
    fn a_margin_reaches_out_and_outside_points_have_no_contact_without_one() {
        let mut none = true;
        BALL.contacts(&at(0.26), &mut |_| none = false);
        assert!(none);
        let mut depth = None;
        BALL.contacts_within(&at(0.26), 0.05, &mut |c| depth = Some(c.depth));
        assert!((depth.unwrap() - 0.04).abs() < 1e-12);
        let mut centre = None;
        BALL.contacts(&BALL.center, &mut |c| centre = Some(c));
        assert_eq!(centre.unwrap().normal, Vec3::y());
    }

    #[test]
    fn may_touch_never_misses_a_contact() {
        for k in 0..2000 {
            let f = k as f64;
            let p = BALL.center
                + Vec3::new((f * 0.37).sin(), (f * 0.73).cos(), (f * 1.3).sin())
                    * (0.2 + (f * 0.011) % 0.2);
            let margin = 0.01 * (k % 7) as f64;
            let mut hit = false;
            BALL.contacts_within(&p, margin, &mut |_| hit = true);
            if hit {
                assert!(BALL.may_touch(&p, &p, margin), "{p:?} {margin}");
            }
        }
        assert!(!BALL.may_touch(&Vec3::new(2.0, 1.0, -0.5), &Vec3::new(3.0, 1.0, -0.5), 0.1));
    }

    #[test]
    fn a_chord_through_the_ball_meets_it_and_one_beside_it_does_not() {
        let c = BALL.center;
        let across = (c + Vec3::new(-0.3, 0.1, 0.0), c + Vec3::new(0.3, 0.1, 0.0));
        assert!(BALL.segment_meets(&across.0, &across.1));
        let beside = (
            c + Vec3::new(-0.3, 0.26, 0.0),
            c + Vec3::new(0.3, 0.26, 0.0),
        );
        assert!(!BALL.segment_meets(&beside.0, &beside.1));
        // Short of the ball, pointing at it.
        let short = (c + Vec3::new(-0.6, 0.0, 0.0), c + Vec3::new(-0.3, 0.0, 0.0));
        assert!(!BALL.segment_meets(&short.0, &short.1));
        assert!(BALL.segment_meets(&c, &c));
    }
}
