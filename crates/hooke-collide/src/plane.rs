//! Planes: the ground `y = h0` and the inclined plane `a x + b y + c z + d = 0` (docs/physics.md §2).

use hooke_core::{Collider, Contact, Vec3};

/// The half-space on one side of the plane `a x + b y + c z + d = 0` is solid.
///
/// With `f(x) = a x + b y + c z + d` and the free side `s` (`+1` or `-1`), a point is inside
/// when `s f(x) < 0`; its depth is `-s f(x) / |(a, b, c)|` and the outward normal
/// `s (a, b, c) / |(a, b, c)|`. These are the formulas of the contract, evaluated as written,
/// rather than parry's `HalfSpace`, so that jello worlds match other implementations of the
/// contract (docs/physics.md §2) to the last bit.
///
/// ```
/// use hooke_collide::Plane;
/// use hooke_core::{Collider, Vec3};
/// let ground = Plane::ground(0.0);
/// assert!(ground.inside(&Vec3::new(0.0, -0.1, 0.0)));
/// assert!((ground.depth(&Vec3::new(0.0, -0.1, 0.0)) - 0.1).abs() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    coefficients: [f64; 4],
    side: f64,
    label: &'static str,
}

impl Plane {
    /// The ground `y = height`, solid below (free side up).
    pub fn ground(height: f64) -> Self {
        Self {
            coefficients: [0.0, 1.0, 0.0, -height],
            side: 1.0,
            label: "ground",
        }
    }

    /// The plane `a x + b y + c z + d = 0` whose free side is the one holding `free_point`
    /// (docs/physics.md §2: the body's initial centroid; a centroid on the plane counts as `+1`).
    /// `None` when `(a, b, c)` is zero or a coefficient is not finite.
    pub fn inclined(coefficients: [f64; 4], free_point: &Vec3) -> Option<Self> {
        let [a, b, c, _] = coefficients;
        if !coefficients.iter().all(|x| x.is_finite()) || (a == 0.0 && b == 0.0 && c == 0.0) {
            return None;
        }
        let probe = Self {
            coefficients,
            side: 1.0,
            label: "inclined plane",
        };
        let side = if probe.f(free_point) < 0.0 { -1.0 } else { 1.0 };
        Some(Self { side, ..probe })
    }

    /// `(a, b, c, d)`.
    pub fn coefficients(&self) -> [f64; 4] {
        self.coefficients
    }

    /// The free side `s`, `+1` or `-1`.
    pub fn side(&self) -> f64 {
        self.side
    }

    fn f(&self, p: &Vec3) -> f64 {
        let [a, b, c, d] = self.coefficients;
        a * p.x + b * p.y + c * p.z + d
    }

    fn norm(&self) -> f64 {
        let [a, b, c, _] = self.coefficients;
        (a * a + b * b + c * c).sqrt()
    }
}

impl Collider for Plane {
    fn name(&self) -> String {
        self.label.to_string()
    }

    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
        let sf = self.side * self.f(p);
        if sf < 0.0 {
            let [a, b, c, _] = self.coefficients;
            let norm = self.norm();
            let depth = -sf / norm;
            let normal = Vec3::new(a, b, c) * self.side / norm;
            sink(Contact {
                depth,
                normal,
                point: p + normal * depth,
            });
        }
    }

    fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
        // The side's distance, a sum of products in a fixed order, is monotone in each
        // coordinate as rounded too: its least over the box is at the corner chosen by
        // the coefficients' signs, and no particle in the box is nearer than that corner.
        let [a, b, c, _] = self.coefficients;
        let pick = |k: f64, lo: f64, hi: f64| if self.side * k >= 0.0 { lo } else { hi };
        let corner = Vec3::new(
            pick(a, lo.x, hi.x),
            pick(b, lo.y, hi.y),
            pick(c, lo.z, hi.z),
        );
        let sf = self.side * self.f(&corner);
        // Written so that NaN answers `true`.
        let clear = if margin == 0.0 {
            sf >= 0.0
        } else {
            sf / self.norm() >= margin
        };
        !clear
    }

    fn is_half_space(&self) -> bool {
        true
    }

    fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
        if margin == 0.0 {
            return self.contacts(p, sink);
        }
        let [a, b, c, _] = self.coefficients;
        let norm = self.norm();
        let distance = self.side * self.f(p) / norm;
        if distance < margin {
            let normal = Vec3::new(a, b, c) * self.side / norm;
            sink(Contact {
                depth: margin - distance,
                normal,
                point: p - normal * distance,
            });
        }
    }
}
