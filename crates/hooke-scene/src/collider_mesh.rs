//! Colliders as triangles, in world coordinates: what the renderer draws and what the OBJ
//! export writes. Unbounded shapes are clipped to a region the caller chooses.

use crate::scene::ColliderGeometry;
use hooke_collide::{Cylinder, Sphere};
use hooke_core::Vec3;
use std::f64::consts::TAU;

/// Segments around the analytic cylinder's circles. Its corners lie on the circles, so the
/// tessellation is inside the true solid, at most `R (1 - cos(π / 64))` (0.72 mm at
/// R = 0.6 m) from its side.
pub const CYLINDER_SEGMENTS: usize = 64;

/// Corner `k` (bits: 4 = x, 2 = y, 1 = z) of the box `min..max`.
pub fn box_corner(min: Vec3, max: Vec3, k: usize) -> Vec3 {
    let pick = |bit: usize, lo: f64, hi: f64| if k & bit != 0 { hi } else { lo };
    Vec3::new(
        pick(4, min.x, max.x),
        pick(2, min.y, max.y),
        pick(1, min.z, max.z),
    )
}

/// The convex polygon where the plane `a x + b y + c z + d = 0` cuts the box `min..max`, its
/// corners in order around the plane's normal (empty when the plane misses the box).
pub fn plane_in_box(coefficients: [f64; 4], min: Vec3, max: Vec3) -> Vec<Vec3> {
    let [a, b, c, d] = coefficients;
    let f = |p: &Vec3| a * p.x + b * p.y + c * p.z + d;
    let corner = |k: usize| box_corner(min, max, k);
    let mut points = Vec::new();
    for k in 0..8 {
        for bit in [1, 2, 4] {
            if k & bit == 0 {
                let (p, q) = (corner(k), corner(k | bit));
                let (fp, fq) = (f(&p), f(&q));
                if (fp <= 0.0) != (fq <= 0.0) {
                    points.push(p + (q - p) * (fp / (fp - fq)));
                }
            }
        }
    }
    if points.len() < 3 {
        return Vec::new();
    }
    let centre = points.iter().sum::<Vec3>() / points.len() as f64;
    let n = Vec3::new(a, b, c).normalize();
    let u = (points[0] - centre).normalize();
    let v = n.cross(&u);
    points.sort_by(|p, q| {
        let ang = |x: &Vec3| (x - centre).dot(&v).atan2((x - centre).dot(&u));
        ang(p).total_cmp(&ang(q))
    });
    points
}

/// A ball's surface: [`hooke_collide::table::ball`] (1280 faces, corners on the sphere, so
/// inside it by at most 0.12 % of the radius) scaled and placed.
pub fn sphere_triangles(s: &Sphere) -> Vec<[Vec3; 3]> {
    let (points, faces) = hooke_collide::table::ball();
    let at = |k: usize| s.center + Vec3::from(points[k]) * s.radius;
    faces.iter().map(|f| f.map(at)).collect()
}

/// The analytic cylinder's surface: the top and bottom discs as fans, the side as quads.
pub fn cylinder_triangles(c: &Cylinder) -> Vec<[Vec3; 3]> {
    let top = c.center.y;
    let bottom = top - c.thickness;
    let rim = |k: usize, y: f64| {
        let a = TAU * k as f64 / CYLINDER_SEGMENTS as f64;
        Vec3::new(
            c.center.x + c.radius * a.cos(),
            y,
            c.center.z + c.radius * a.sin(),
        )
    };
    let (up, down) = (
        Vec3::new(c.center.x, top, c.center.z),
        Vec3::new(c.center.x, bottom, c.center.z),
    );
    let mut out = Vec::with_capacity(4 * CYLINDER_SEGMENTS);
    for k in 0..CYLINDER_SEGMENTS {
        let j = k + 1;
        out.push([up, rim(j, top), rim(k, top)]);
        out.push([rim(k, bottom), rim(j, top), rim(j, bottom)]);
        out.push([rim(k, bottom), rim(k, top), rim(j, top)]);
        out.push([down, rim(k, bottom), rim(j, bottom)]);
    }
    out
}

impl ColliderGeometry {
    /// The collider's surface as triangles. The ground is a square of half-side `half`
    /// around `centre` (at the ground's height); an inclined plane is clipped to the box
    /// `region`; the box interior gives its six walls.
    pub fn triangles(&self, centre: Vec3, half: f64, region: (Vec3, Vec3)) -> Vec<[Vec3; 3]> {
        match self {
            Self::Ground(h) => {
                let p = |dx: f64, dz: f64| Vec3::new(centre.x + dx, *h, centre.z + dz);
                vec![
                    [p(-half, -half), p(-half, half), p(half, half)],
                    [p(-half, -half), p(half, half), p(half, -half)],
                ]
            }
            Self::Plane(coefficients) => {
                let poly = plane_in_box(*coefficients, region.0, region.1);
                let n = poly.len();
                (1..n.saturating_sub(1))
                    .map(|k| [poly[0], poly[k], poly[k + 1]])
                    .collect()
            }
            Self::Box(b) => {
                let c = |k| box_corner(b.min, b.max, k);
                // Each wall as two triangles.
                hooke_collide::BOX_FACES
                    .iter()
                    .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
                    .collect()
            }
            Self::Cylinder(cyl) => cylinder_triangles(cyl),
            Self::Sphere(ball) => sphere_triangles(ball),
            Self::Mesh(tris) => tris.clone(),
        }
    }

    /// A short name of the collider's kind: `ground`, `plane`, `box`, `cylinder`, `sphere`,
    /// `mesh`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Ground(_) => "ground",
            Self::Plane(_) => "plane",
            Self::Box(_) => "box",
            Self::Cylinder(_) => "cylinder",
            Self::Sphere(_) => "sphere",
            Self::Mesh(_) => "mesh",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cylinder_tessellation_stays_inside_the_solid() {
        let c = Cylinder {
            center: Vec3::new(0.1, 1.0, -0.2),
            radius: 0.6,
            thickness: 0.04,
        };
        for t in cylinder_triangles(&c) {
            for p in t {
                let r = ((p.x - 0.1).powi(2) + (p.z + 0.2).powi(2)).sqrt();
                assert!(r <= 0.6 + 1e-12 && (0.96 - 1e-12..=1.0 + 1e-12).contains(&p.y));
            }
        }
    }

    #[test]
    fn a_plane_through_a_box_is_a_closed_fan() {
        let g = ColliderGeometry::Plane([1.0, 1.0, 0.0, 0.0]);
        let tris = g.triangles(Vec3::zeros(), 1.0, (Vec3::repeat(-2.0), Vec3::repeat(2.0)));
        // A rectangle 4 m by 4√2 m: two triangles of total area 16√2.
        let area: f64 = tris
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).cross(&(t[2] - t[0])).norm())
            .sum();
        assert!((area - 16.0 * 2f64.sqrt()).abs() < 1e-9, "{area}");
    }
}
