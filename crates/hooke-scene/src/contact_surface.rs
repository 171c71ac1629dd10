//! A body's contact surface as built: its thickness, self-collision and friction from its
//! spec or the defaults for its shape (docs/physics.md §3.1).

use crate::error::{BuildError, invalid};
use crate::spec::*;
use hooke_core::{DEFAULT_CLOTH_THICKNESS, DEFAULT_SURFACE_FRICTION, Surface, Vec3};
use std::ops::Range;

/// The contact thickness a body with a surface gets when its spec gives none: for a grid
/// the cloth default, at most a quarter of the spacing so that a fine cloth's neighbours
/// never touch; none for other shapes.
pub(crate) fn default_thickness(shape: &ShapeSpec) -> f64 {
    match shape {
        ShapeSpec::Grid { spacing, .. } => DEFAULT_CLOTH_THICKNESS.min(0.25 * spacing.get()),
        _ => 0.0,
    }
}

/// The contact surface of a body: its triangles with the thickness, self-collision and
/// friction its spec gives or the defaults for its shape.
pub(crate) fn body_surface(
    body: &BodySpec,
    key: &str,
    local: &[Vec3],
    particles: Range<usize>,
    triangles: Vec<[u32; 3]>,
) -> Result<Surface, BuildError> {
    // A body without triangles (a chain, points, a grid one particle wide) has no surface:
    // its default thickness is none, and contact keys written for it are refused by name.
    let default = if triangles.is_empty() {
        0.0
    } else if let ShapeSpec::Mesh { .. } = body.shape {
        // As a grid's: at most a quarter of the shortest edge, so that the contacts between
        // a mesh's own neighbours hold its slivers uncrushed (a thicker one, given, is
        // accepted: the pairs its structure holds apart at rest are never contacts).
        DEFAULT_CLOTH_THICKNESS.min(0.25 * shortest_edge(local, particles.start, &triangles))
    } else {
        default_thickness(&body.shape)
    };
    let thickness = body.thickness.map_or(default, |h| h.get());
    if triangles.is_empty() {
        let written = [
            ("thickness", body.thickness.is_some_and(|h| h.get() > 0.0)),
            ("self_collision", body.self_collision.is_some()),
            ("friction", body.friction.is_some()),
        ];
        if let Some((name, _)) = written.iter().find(|(_, w)| *w) {
            return Err(invalid(
                format!("{key}.{name}"),
                "only bodies with a surface (a grid or lattice at least 2 particles wide) take \
                 contact keys; this body has no triangles: remove it",
            ));
        }
    }
    let self_collision = body.self_collision.unwrap_or(true);
    let surface = Surface {
        particles,
        triangles,
        thickness,
        self_collision,
        friction: body.friction.map_or(DEFAULT_SURFACE_FRICTION, |f| f.get()),
    };
    Ok(surface)
}

/// The shortest edge of `triangles` (particle indices, the body's first being `start`) in
/// the rest shape `local`, which is what the springs keep.
fn shortest_edge(local: &[Vec3], start: usize, triangles: &[[u32; 3]]) -> f64 {
    let rest = |i: u32| local[i as usize - start];
    triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (rest(a) - rest(b)).norm())
        .fold(f64::INFINITY, f64::min)
}

impl SceneSpec {
    /// The scene with the contact keys its surfaces default to written out (`thickness`,
    /// `self_collision`, `friction` on every body with triangles), so that an emitted scene
    /// shows them; it builds to the same simulation, bit for bit.
    pub fn with_contact_defaults(&self) -> SceneSpec {
        let mut spec = self.clone();
        for body in &mut spec.bodies {
            // A grid has triangles when it is two particles wide both ways, a lattice when
            // two of its sides are (crate::surface::triangles), without making them.
            let wide = |sides: &[usize]| sides.iter().filter(|&&n| n >= 2).count();
            let surface = match &body.shape {
                ShapeSpec::Grid { size, .. } => wide(size) == 2,
                ShapeSpec::Lattice { size, .. } => wide(size) >= 2,
                _ => false,
            };
            if !surface {
                continue;
            }
            let thickness = default_thickness(&body.shape);
            body.thickness.get_or_insert(NonNegative::of(thickness));
            body.self_collision.get_or_insert(true);
            body.friction
                .get_or_insert(NonNegative::of(DEFAULT_SURFACE_FRICTION));
        }
        spec
    }
}
