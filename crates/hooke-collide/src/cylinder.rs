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
