//! The analytic cylinder tabletop of the course document.

use crate::bounds::{boxes_meet, touch_reach};
use hooke_core::{Circle, Collider, Contact, Feature, Vec3};

/// A solid vertical disc: top face at `y = Y`, bottom at `Y - thickness`, radius `R` about
/// the vertical axis through `(X, Z)`.
///
/// Inside when `(x-X)² + (z-Z)² < R²` and `Y - h < y < Y`; the contact is with the nearest of
/// the top, bottom and side faces (ties go to the top, then the side).
///
/// ```
/// use hooke_collide::Cylinder;
/// use hooke_core::{Collider, Vec3};
/// let table = Cylinder { center: Vec3::new(0.0, 1.0, 0.0), radius: 0.5, thickness: 0.05 };
/// let mut hit = None;
/// table.contacts(&Vec3::new(0.1, 0.99, 0.0), &mut |c| hit = Some(c));
/// let c = hit.unwrap();
/// assert_eq!(c.normal, Vec3::new(0.0, 1.0, 0.0));
/// assert!((c.depth - 0.01).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// Centre of the top face `(X, Y, Z)`, metres.
    pub center: Vec3,
    /// Radius `R`, metres.
    pub radius: f64,
    /// Thickness `h`, metres.
    pub thickness: f64,
}

impl Cylinder {
    /// The rims of the top (`y = Y`) and bottom (`y = Y - h`) faces.
    pub fn rims(&self) -> [Circle; 2] {
        [0.0, self.thickness].map(|drop| Circle {
            center: self.center - Vec3::y() * drop,
            axis: Vec3::y(),
            radius: self.radius,
        })
    }

    /// The nearest point of the solid to `p` outside it, and the outward normal there.
    fn nearest_outside(&self, p: &Vec3) -> (Vec3, Vec3) {
        let (dx, dz) = (p.x - self.center.x, p.z - self.center.z);
        let r = (dx * dx + dz * dz).sqrt();
        let top = self.center.y;
        let bottom = top - self.thickness;
        let scale = if r > self.radius {
            self.radius / r
        } else {
            1.0
        };
        let q = Vec3::new(
            self.center.x + dx * scale,
            p.y.clamp(bottom, top),
            self.center.z + dz * scale,
        );
        let d = p - q;
        let normal = match d.try_normalize(0.0) {
            Some(n) => n,
            // On the surface itself: the face it lies on.
            None if p.y >= top => Vec3::y(),
            None if p.y <= bottom => -Vec3::y(),
            None => Vec3::new(dx / r, 0.0, dz / r),
        };
        (q, normal)
    }
}

impl Collider for Cylinder {
    fn name(&self) -> String {
        "cylinder".to_string()
    }

    fn thickness(&self) -> Option<f64> {
        Some(self.thickness.min(2.0 * self.radius))
    }

    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
        let (dx, dz) = (p.x - self.center.x, p.z - self.center.z);
        let r2 = dx * dx + dz * dz;
        let top = self.center.y;
        let bottom = top - self.thickness;
        if !(r2 < self.radius * self.radius && bottom < p.y && p.y < top) {
            return;
        }
        let r = r2.sqrt();
        let to_top = top - p.y;
        let to_bottom = p.y - bottom;
        let to_side = self.radius - r;
        let contact = if to_top <= to_side && to_top <= to_bottom {
            let n = Vec3::new(0.0, 1.0, 0.0);
            Contact {
                depth: to_top,
                normal: n,
                point: Vec3::new(p.x, top, p.z),
            }
        } else if to_side <= to_bottom && r > 0.0 {
            let n = Vec3::new(dx / r, 0.0, dz / r);
            let point = Vec3::new(
                self.center.x + n.x * self.radius,
                p.y,
                self.center.z + n.z * self.radius,
            );
            Contact {
                depth: to_side,
                normal: n,
                point,
            }
        } else {
            let n = Vec3::new(0.0, -1.0, 0.0);
            Contact {
                depth: to_bottom,
                normal: n,
                point: Vec3::new(p.x, bottom, p.z),
            }
        };
        sink(contact);
    }

    /// Whether the part of the segment between the top and bottom planes comes nearer the
    /// axis than the radius.
    fn segment_meets(&self, a: &Vec3, b: &Vec3) -> bool {
        let (top, bottom) = (self.center.y, self.center.y - self.thickness);
        let ab = b - a;
        // The segment's span of parameters within the slab.
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        if ab.y == 0.0 {
            if !(bottom < a.y && a.y < top) {
                return false;
            }
        } else {
            let (u, v) = ((bottom - a.y) / ab.y, (top - a.y) / ab.y);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
            if t0 >= t1 {
                return false;
            }
        }
        // The nearest approach to the axis over that span, in the x-z plane.
        let (px, pz) = (a.x - self.center.x, a.z - self.center.z);
        let (dx, dz) = (ab.x, ab.z);
        let len2 = dx * dx + dz * dz;
        let t = if len2 > 0.0 {
            (-(px * dx + pz * dz) / len2).clamp(t0, t1)
        } else {
            t0
        };
        let (x, z) = (px + dx * t, pz + dz * t);
        x * x + z * z < self.radius * self.radius
    }

    /// Whether the box, grown by `margin` (and a little for rounding), meets the solid's
    /// bounds.
    fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
        let c = self.center;
        let (a, b) = (
            Vec3::new(c.x - self.radius, c.y - self.thickness, c.z - self.radius),
            Vec3::new(c.x + self.radius, c.y, c.z + self.radius),
        );
        boxes_meet(lo, hi, &a, &b, touch_reach(lo, hi, margin))
    }

    /// Inside: the nearest face, `margin` further out. Outside: the nearest point of the
    /// solid (on a face or a rim), when nearer than `margin`.
    fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
        let mut inside = false;
        self.contacts(p, &mut |mut c| {
            inside = true;
            c.depth += margin;
            sink(c);
        });
        if inside || margin == 0.0 {
            return;
        }
        let (point, normal) = self.nearest_outside(p);
        let distance = (p - point).norm();
        if distance < margin {
            sink(Contact {
                depth: margin - distance,
                normal,
                point,
            });
        }
    }

    fn features(&self, lo: &Vec3, hi: &Vec3, sink: &mut dyn FnMut(hooke_core::Feature)) {
        for rim in self.rims() {
            let (a, b) = Feature::Circle(rim).bounds();
            if (0..3).all(|k| a[k] <= hi[k] && lo[k] <= b[k]) {
                sink(Feature::Circle(rim));
            }
        }
    }

    fn has_features(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLE: Cylinder = Cylinder {
        center: Vec3::new(0.0, 1.0, 0.0),
        radius: 0.5,
        thickness: 0.05,
    };

    #[test]
    fn a_segment_meets_the_disc_only_through_its_inside() {
        let meets = |a: [f64; 3], b: [f64; 3]| {
            TABLE.segment_meets(&Vec3::new(a[0], a[1], a[2]), &Vec3::new(b[0], b[1], b[2]))
        };
        // Down through the top, and sideways through the rim's thickness.
        assert!(meets([0.1, 1.2, 0.0], [0.1, 0.8, 0.0]));
        assert!(meets([-0.8, 0.98, 0.0], [0.8, 0.98, 0.1]));
        // A cloth edge over the rim, from the top to the side: through the corner.
        assert!(meets([0.45, 1.005, 0.0], [0.55, 0.94, 0.0]));
        // Above the top, beside the side, below the bottom: not.
        assert!(!meets([-0.8, 1.01, 0.0], [0.8, 1.01, 0.0]));
        assert!(!meets([0.6, 1.2, 0.0], [0.6, 0.8, 0.0]));
        assert!(!meets([0.0, 0.9, 0.0], [0.3, 0.94, 0.0]));
        // Steep past the rim without entering: from above the top outside the radius.
        assert!(!meets([0.52, 1.1, 0.0], [0.6, 0.9, 0.0]));
        // Each end inside.
        assert!(meets([0.0, 0.99, 0.0], [0.0, 0.99, 0.0]));
    }
}
