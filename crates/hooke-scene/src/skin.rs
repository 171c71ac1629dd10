//! What a body looks like outside Hooke: the vertices and faces that are drawn and
//! exported. For a body made from a mesh these are the user's own, in the file's count and
//! order, each vertex following the particles; for generated bodies, the particles and
//! their surface triangles.

use hooke_core::Vec3;

/// How one vertex of the user's mesh follows the simulation.
#[derive(Clone, Debug, PartialEq)]
pub enum SkinVertex {
    /// It is this particle (a simulation index); welded vertices share one.
    Particle(u32),
    /// It is in no face, so it simulates nothing: it stays where the body placed it.
    Fixed(Vec3),
    /// It rides a lattice cell: the weighted sum of its eight corners (simulation indices),
    /// trilinear weights summing to 1.
    Embedded {
        /// The cell's corners.
        corners: [u32; 8],
        /// Their weights.
        weights: [f64; 8],
    },
}

/// One face of the user's mesh: vertex indices into [`Skin::vertices`] as written, and
/// texture coordinates into [`Skin::uvs`] when the file gives them.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinFace {
    /// Vertex indices, in the file's winding.
    pub corners: Vec<u32>,
    /// Texture coordinate indices, one per corner.
    pub uvs: Option<Vec<u32>>,
}

/// The user's mesh carried by a body.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skin {
    /// Every vertex of the file, in its order.
    pub vertices: Vec<SkinVertex>,
    /// Every face of the file, in its order, zero-area ones included (they are drawn as
    /// nothing and simulate nothing).
    pub faces: Vec<SkinFace>,
    /// The file's texture coordinates.
    pub uvs: Vec<[f64; 2]>,
}

impl Skin {
    /// The faces and texture coordinates of an OBJ as written, with `vertices` for its
    /// vertices.
    pub(crate) fn of_file(mesh: &hooke_collide::PolygonMesh, vertices: Vec<SkinVertex>) -> Self {
        Self {
            vertices,
            faces: mesh
                .faces
                .iter()
                .map(|f| SkinFace {
                    corners: f.corners.clone(),
                    uvs: f.uvs.clone(),
                })
                .collect(),
            uvs: mesh.texcoords.clone(),
        }
    }

    /// Each vertex's position from the particles' `x`, into `out` (cleared first).
    pub fn positions(&self, x: &[Vec3], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend(self.vertices.iter().map(|v| v.at(x)));
    }

    /// The faces as triangles (fans of polygons) of vertex indices: what is drawn.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::with_capacity(self.faces.len() * 2);
        for f in &self.faces {
            for k in 1..f.corners.len().saturating_sub(1) {
                out.push([f.corners[0], f.corners[k], f.corners[k + 1]]);
            }
        }
        out
    }
}

impl SkinVertex {
    /// Where the vertex is, given the particles' positions (or velocities: the weights are
    /// the same, so a vertex's velocity is the same sum of the particles').
    pub fn at(&self, x: &[Vec3]) -> Vec3 {
        match self {
            Self::Particle(i) => x[*i as usize],
            Self::Fixed(p) => *p,
            Self::Embedded { corners, weights } => corners
                .iter()
                .zip(weights)
                .fold(Vec3::zeros(), |sum, (&c, &w)| sum + x[c as usize] * w),
        }
    }

    /// The vertex of a body whose particles start at `start`, placed by `rotation` and
    /// `origin` as the body is (a fixed vertex is moved with it; the others follow their
    /// particles).
    pub(crate) fn offset(
        &mut self,
        start: u32,
        rotation: &nalgebra::Rotation3<f64>,
        origin: &Vec3,
    ) {
        match self {
            Self::Particle(i) => *i += start,
            Self::Fixed(p) => *p = origin + rotation * *p,
            Self::Embedded { corners, .. } => {
                for c in corners {
                    *c += start;
                }
            }
        }
    }

    /// [`SkinVertex::at`] for a velocity: a fixed vertex does not move.
    pub fn velocity(&self, v: &[Vec3]) -> Vec3 {
        match self {
            Self::Fixed(_) => Vec3::zeros(),
            _ => self.at(v),
        }
    }
}
