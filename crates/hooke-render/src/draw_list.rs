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

/// A smooth-shaded triangle mesh whose triangles share corners by index: each corner is
/// projected once per frame however many triangles hold it, and the list stores a position
/// and a normal per corner instead of three of each per triangle (for a cloth grid, a fifth
/// of the bytes of the same surface as [`Triangle`]s). Without per-corner colours, drawn
/// exactly as the [`Triangle`]s it expands to ([`Mesh::triangle`]).
///
/// ```
/// use hooke_render::{DrawList, Mesh};
/// use nalgebra::Vector3;
/// // A unit square in the x-y plane from two triangles sharing an edge.
/// let positions = vec![Vector3::zeros(), Vector3::x(), Vector3::new(1.0, 1.0, 0.0), Vector3::y()];
/// let mesh = Mesh {
///     normals: vec![Vector3::z(); 4],
///     positions,
///     triangles: vec![[0, 1, 2], [0, 2, 3]],
///     color: [0.2, 0.45, 0.8],
///     colors: Vec::new(),
/// };
/// assert_eq!(mesh.triangle(1).unwrap().p[2], Vector3::y());
/// let mut list = DrawList::default();
/// list.meshes.push(mesh);
/// assert_eq!(list.triangle_count(), 2);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Corner positions, metres.
    pub positions: Vec<Vector3<f64>>,
    /// A unit normal per corner (either side faces the light).
    pub normals: Vec<Vector3<f64>>,
    /// Corner indices of each triangle. A triangle naming a corner that does not exist (or
    /// has no normal) is not drawn.
    pub triangles: Vec<[u32; 3]>,
    /// Base colour of the whole mesh.
    pub color: Rgb,
    /// A colour per corner, interpolated across each triangle (a quantity's colour map);
    /// empty: the whole mesh is `color`.
    pub colors: Vec<Rgb>,
}

impl Mesh {
    /// Triangle `k` as a free-standing [`Triangle`], or `None` when it is out of range or
    /// names a missing corner.
    pub fn triangle(&self, k: usize) -> Option<Triangle> {
        let corners = self.triangles.get(k)?;
        let [p, n] = [&self.positions, &self.normals].map(|v| {
            let mut out = [Vector3::zeros(); 3];
            for (o, &c) in out.iter_mut().zip(corners) {
                *o = *v.get(c as usize)?;
            }
            Some(out)
        });
        Some(Triangle {
            p: p?,
            n: n?,
            color: self.color,
        })
    }
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

/// Everything in one frame. Where two primitives are at the same depth, the one earlier in
/// this order shows: meshes (in order, each's triangles in order), triangles, lines, points.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DrawList {
    /// Smooth-shaded indexed meshes (the bodies' surfaces).
    pub meshes: Vec<Mesh>,
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

    /// Triangles of meshes and free-standing ones together.
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.triangles.len()).sum::<usize>() + self.triangles.len()
    }

    /// The bounding box of every primitive, if there is any (a mesh's corners count whether
    /// or not a triangle uses them).
    pub fn bounds(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let points = self
            .meshes
            .iter()
            .flat_map(|m| m.positions.iter().copied())
            .chain(self.triangles.iter().flat_map(|t| t.p))
            .chain(self.lines.iter().flat_map(|l| [l.a, l.b]))
            .chain(self.points.iter().map(|p| p.p));
        points.fold(None, |acc, p| match acc {
            None => Some((p, p)),
            Some((lo, hi)) => Some((lo.inf(&p), hi.sup(&p))),
        })
    }
}
