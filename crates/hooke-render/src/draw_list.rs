//! What to draw: world-space primitives with colours. Knows nothing of physics.

use nalgebra::Vector3;

/// A linear RGB colour, components in `[0, 1]`.
pub type Rgb = [f32; 3];

/// A triangle with per-vertex normals, lit and shaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Corners, metres.
    pub p: [Vector3<f64>; 3],
    /// Unit normals at the corners (either side faces the light: surfaces are two-sided).
    pub n: [Vector3<f64>; 3],
    /// Base colour.
    pub color: Rgb,
}

/// A line segment drawn `width` pixels wide, unlit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// End points, metres.
    pub a: Vector3<f64>,
    /// End points, metres.
    pub b: Vector3<f64>,
    /// Colour.
    pub color: Rgb,
    /// Width in output pixels.
    pub width: f32,
}

/// A point drawn as a shaded ball `radius` pixels across.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Centre, metres.
    pub p: Vector3<f64>,
    /// Colour.
    pub color: Rgb,
    /// Radius in output pixels.
    pub radius: f32,
}

/// Everything in one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DrawList {
    /// Shaded triangles.
    pub triangles: Vec<Triangle>,
    /// Lines.
    pub lines: Vec<Line>,
    /// Points.
    pub points: Vec<Point>,
}

impl DrawList {
    /// Adds a flat-shaded triangle (its face normal at all corners).
    pub fn flat(&mut self, p: [Vector3<f64>; 3], color: Rgb) {
        let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
        let n = if n.norm() > 0.0 {
            n.normalize()
        } else {
            Vector3::y()
        };
        self.triangles.push(Triangle {
            p,
            n: [n; 3],
            color,
        });
    }

    /// The bounding box of every primitive, if there is any.
    pub fn bounds(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let points = self
            .triangles
            .iter()
            .flat_map(|t| t.p)
            .chain(self.lines.iter().flat_map(|l| [l.a, l.b]))
            .chain(self.points.iter().map(|p| p.p));
        points.fold(None, |acc, p| match acc {
            None => Some((p, p)),
            Some((lo, hi)) => Some((lo.inf(&p), hi.sup(&p))),
        })
    }
}
