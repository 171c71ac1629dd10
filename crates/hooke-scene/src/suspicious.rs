//! What a scene as built does that its author probably did not mean: bodies that start
//! inside a collider, cloth that starts below the top of a table it hangs over (it falls
//! beside or under the table and wraps its pedestal instead of landing on it), tables of a
//! single triangle. Said as warnings: such scenes still run.

use crate::scene::{ColliderGeometry, Scene};
use hooke_core::{Num, Vec3};

/// The top height and horizontal extent (`[x_min, z_min]`, `[x_max, z_max]`) of a table-like
/// collider: a mesh or the analytic cylinder.
fn table_extent(geometry: &ColliderGeometry) -> Option<(f64, [f64; 2], [f64; 2])> {
    match geometry {
        ColliderGeometry::Cylinder(c) => Some((
            c.center.y,
            [c.center.x - c.radius, c.center.z - c.radius],
            [c.center.x + c.radius, c.center.z + c.radius],
        )),
        ColliderGeometry::Mesh(triangles) if !triangles.is_empty() => {
            let points = triangles.iter().flatten();
            let (lo, hi) = points.fold(
                (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |(lo, hi), p| (lo.inf(p), hi.sup(p)),
            );
            Some((hi.y, [lo.x, lo.z], [hi.x, hi.z]))
        }
        _ => None,
    }
}

impl Scene {
    /// Warnings about the scene as built (see the module's documentation), one line each;
    /// none for the built-in scenes.
    pub fn warnings(&self) -> Vec<String> {
        let mut said = Vec::new();
        let x = &self.simulation.particles().x;
        let slots = &self.simulation.model().colliders;
        for (k, geometry) in self.colliders.iter().enumerate() {
            if let ColliderGeometry::Mesh(triangles) = geometry
                && triangles.len() == 1
            {
                said.push(format!(
                    "collider[{k}] is a mesh of a single triangle: an open sheet, not a table"
                ));
            }
        }
        for body in &self.bodies {
            let points = &x[body.range.clone()];
            for (k, slot) in slots.iter().enumerate() {
                let inside = points.iter().filter(|p| slot.shape.inside(p)).count();
                if inside > 0 {
                    said.push(format!(
                        "body '{}' starts with {inside} of its {} particles inside collider[{k}] \
                         ({}): they are pushed out in the first steps",
                        body.name,
                        points.len(),
                        slot.shape.name()
                    ));
                }
            }
            if body.triangles.is_empty() {
                continue;
            }
            for (k, geometry) in self.colliders.iter().enumerate() {
                let Some((top, lo, hi)) = table_extent(geometry) else {
                    continue;
                };
                let over =
                    |p: &&Vec3| (lo[0]..=hi[0]).contains(&p.x) && (lo[1]..=hi[1]).contains(&p.z);
                let below = points.iter().filter(over).filter(|p| p.y < top).count();
                if below > 0 {
                    said.push(format!(
                        "body '{}' starts with {below} particles over collider[{k}] but below its \
                         top (y = {} m): it falls beside or under the table instead of onto it; \
                         raise the body's origin above the top",
                        body.name,
                        Num(top)
                    ));
                }
            }
        }
        said
    }
}
