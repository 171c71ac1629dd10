//! The analytic cylinder tabletop of the course document.

use hooke_core::{Collider, Contact, Vec3};

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
}
