//! A mesh collider whose vertices move: an OBJ's faces animated by a vertex cache (PC2),
//! as a character's arm bent by its armature is (docs/physics.md §2.1, "A deforming
//! collider").
//!
//! The surface at time `t` is the mesh's triangles on the cache's positions at `t`. A
//! material point of the surface is a fixed barycentric combination of its triangle's
//! corners, so it moves by at most the most any of those corners moves: that is the sweep
//! bound the large step splits on, and what the velocity and the carried point of a
//! contact are made of. Each pose is a parry mesh built anew from the positions; the
//! corners the file repeats are welded once, from the mesh as written, and must stay
//! together in every sample.

use crate::cache::VertexCache;
use crate::obj::{MeshError, MeshPart, Placement};
use crate::polygons::PolygonMesh;
use crate::shells::{shells, welded};
use crate::trimesh::TriMeshCollider;
use hooke_core::{Collider, Contact, Feature, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How far apart two corners the mesh file puts at one position may drift in the cache
/// before the surface counts as torn, metres: f32 rounding of a metre-sized scene.
const WELD_DRIFT: f64 = 1e-5;

/// One connected piece of the surface: its vertices (welded ids) and its triangles in
/// indices into them.
#[derive(Clone, Debug)]
struct Piece {
    vertices: Vec<u32>,
    triangles: Vec<[u32; 3]>,
}

/// The surface at one time: every welded vertex's position and the collider built on them.
#[derive(Clone, Debug)]
struct Pose {
    t: f64,
    x: Vec<Vec3>,
    mesh: TriMeshCollider,
}

/// What moves a deforming mesh, without its poses: the cache, the welded corners and the
/// pieces; shared with whoever draws it ([`DeformingMesh::animation`]).
#[derive(Debug)]
pub struct MeshAnimation {
    cache: VertexCache,
    /// Per welded id, the file vertex that stands for it.
    first: Vec<u32>,
    pieces: Vec<Piece>,
}

impl MeshAnimation {
    /// The cache it follows.
    pub fn cache(&self) -> &VertexCache {
        &self.cache
    }

    /// The surface's triangles at time `t`, for drawing.
    pub fn triangles_at(&self, t: f64) -> Vec<[Vec3; 3]> {
        let mut x = Vec::new();
        self.cache.at(t, &mut x);
        self.pieces
            .iter()
            .flat_map(|p| {
                p.triangles
                    .iter()
                    .map(|tri| tri.map(|i| x[self.first[p.vertices[i as usize] as usize] as usize]))
            })
            .collect()
    }
}

/// A mesh collider animated by a vertex cache (see the module's documentation).
#[derive(Clone, Debug)]
pub struct DeformingMesh {
    label: String,
    path: PathBuf,
    animation: Arc<MeshAnimation>,
    before: Pose,
    now: Pose,
    /// A scratch buffer for the cache's positions.
    scratch: Vec<Vec3>,
}

impl DeformingMesh {
    /// The mesh `mesh` (read as written, in the file's coordinates) animated by `cache`
    /// (its positions already placed), named `label` in messages, at time 0; `path` is the
    /// cache's, for errors.
    ///
    /// Refused: a mesh with no face, two corners the mesh puts at one position that part
    /// in some sample (the surface would tear: its topology would change between frames),
    /// and a sample on which no surface can be built (every triangle of a piece without
    /// area), each naming the sample.
    pub fn new(
        label: impl Into<String>,
        mesh: &PolygonMesh,
        placement: &Placement,
        cache: VertexCache,
        path: &Path,
    ) -> Result<Self, MeshError> {
        if mesh.faces.is_empty() {
            return Err(MeshError::Cache {
                path: path.to_path_buf(),
                reason: "the mesh it animates has no face (expected an OBJ with 'f' lines)".into(),
            });
        }
        let placed: Vec<Vec3> = mesh.positions.iter().map(|p| placement.apply(p)).collect();
        let (ids, first) = weld(&placed);
        let triangles: Vec<[u32; 3]> = mesh
            .faces
            .iter()
            .flat_map(|f| {
                (1..f.corners.len() - 1)
                    .map(move |k| [f.corners[0], f.corners[k], f.corners[k + 1]])
            })
            .map(|t| t.map(|i| ids[i as usize]))
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
            .collect();
        for k in 0..cache.len() {
            let x = cache.sample(k);
            for (v, &id) in ids.iter().enumerate() {
                let f = first[id as usize] as usize;
                let apart = (x[v] - x[f]).norm();
                if apart > WELD_DRIFT {
                    return Err(MeshError::Cache {
                        path: path.to_path_buf(),
                        reason: format!(
                            "vertices {} and {} are one corner in the mesh but {apart:.3e} m \
                             apart in sample {k}: the collider's surface would tear (its \
                             topology would change between frames); expected the cache of \
                             this mesh, or weld the corners in it",
                            f + 1,
                            v + 1
                        ),
                    });
                }
            }
        }
        let pieces = pieces(&triangles, first.len());
        let label = label.into();
        let welded =
            |sample: &[Vec3]| -> Vec<Vec3> { first.iter().map(|&f| sample[f as usize]).collect() };
        // Every sample must make a surface; the poses between them have the same faces.
        for k in 0..cache.len() {
            surface(&label, &pieces, &welded(cache.sample(k)), path).map_err(|e| match e {
                MeshError::Build { part, reason, .. } => MeshError::Cache {
                    path: path.to_path_buf(),
                    reason: format!("sample {k}, {part}: {reason}"),
                },
                e => e,
            })?;
        }
        let mut scratch = Vec::new();
        cache.at(0.0, &mut scratch);
        let x = welded(&scratch);
        let start = Pose {
            t: 0.0,
            mesh: surface(&label, &pieces, &x, path)?,
            x,
        };
        Ok(Self {
            label,
            path: path.to_path_buf(),
            animation: Arc::new(MeshAnimation {
                cache,
                first,
                pieces,
            }),
            before: start.clone(),
            now: start,
            scratch,
        })
    }

    /// Whether every piece is closed (a solid).
    pub fn is_closed(&self) -> bool {
        self.now.mesh.is_closed()
    }

    /// Its cache and pieces, to draw it at any time.
    pub fn animation(&self) -> Arc<MeshAnimation> {
        Arc::clone(&self.animation)
    }

    /// Every welded vertex's position at `t`.
    fn positions(&mut self, t: f64) -> Vec<Vec3> {
        self.animation.cache.at(t, &mut self.scratch);
        self.animation
            .first
            .iter()
            .map(|&f| self.scratch[f as usize])
            .collect()
    }

    fn pose(&mut self, t: f64) -> Pose {
        let x = self.positions(t);
        // Every sample was built when the collider was, and a pose between two has the
        // same faces, so this builds; were it ever not to, the surface holds where it was.
        match surface(&self.label, &self.animation.pieces, &x, &self.path) {
            Ok(mesh) => Pose { t, x, mesh },
            Err(_) => Pose {
                t,
                ..self.now.clone()
            },
        }
    }

    /// How far the material point of `pose`'s surface nearest `p` moves from the step's
    /// start to its end.
    fn travel(&self, pose: &Pose, p: &Vec3) -> Vec3 {
        let Some((k, corners, w)) = pose.mesh.locate(p) else {
            return Vec3::zeros();
        };
        let piece = &self.animation.pieces[k];
        (0..3)
            .map(|c| {
                let g = piece.vertices[corners[c] as usize] as usize;
                (self.now.x[g] - self.before.x[g]) * w[c]
            })
            .sum()
    }
}

/// The collider made of `pieces` on the welded positions `x`.
fn surface(
    label: &str,
    pieces: &[Piece],
    x: &[Vec3],
    path: &Path,
) -> Result<TriMeshCollider, MeshError> {
    let parts = pieces
        .iter()
        .enumerate()
        .map(|(k, p)| MeshPart {
            name: format!("piece {}", k + 1),
            vertices: p.vertices.iter().map(|&g| x[g as usize]).collect(),
            triangles: p.triangles.clone(),
        })
        .collect();
    TriMeshCollider::exact(label.to_string(), parts, path)
}

/// Per position, its welded id ([`welded`]: the copies of one corner a file repeats), and
/// per id the first position that has it.
fn weld(x: &[Vec3]) -> (Vec<u32>, Vec<u32>) {
    let ids = welded(x);
    let mut first = Vec::new();
    for (i, &id) in ids.iter().enumerate() {
        // Ids are numbered as positions first appear: a new one is the next number.
        if id as usize == first.len() {
            first.push(i as u32);
        }
    }
    (ids, first)
}

/// The connected pieces of `triangles` (over `count` welded vertices, [`shells`]), each
/// with its own vertices, in the order of their first triangle.
fn pieces(triangles: &[[u32; 3]], count: usize) -> Vec<Piece> {
    let shell = shells(triangles, count);
    let mut index: HashMap<u32, usize> = HashMap::new();
    let mut out: Vec<(Piece, HashMap<u32, u32>)> = Vec::new();
    for (t, s) in triangles.iter().zip(shell) {
        let k = *index.entry(s).or_insert_with(|| {
            out.push((
                Piece {
                    vertices: Vec::new(),
                    triangles: Vec::new(),
                },
                HashMap::new(),
            ));
            out.len() - 1
        });
        let (piece, local) = &mut out[k];
        let tri = t.map(|g| {
            *local.entry(g).or_insert_with(|| {
                piece.vertices.push(g);
                piece.vertices.len() as u32 - 1
            })
        });
        piece.triangles.push(tri);
    }
    out.into_iter().map(|(p, _)| p).collect()
}

impl Collider for DeformingMesh {
    fn name(&self) -> String {
        self.label.clone()
    }

    fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
        self.now.mesh.contacts(p, sink);
    }

    fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
        self.now.mesh.contacts_within(p, margin, sink);
    }

    fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
        self.now.mesh.may_touch(lo, hi, margin)
    }

    fn features(&self, lo: &Vec3, hi: &Vec3, sink: &mut dyn FnMut(Feature)) {
        self.now.mesh.features(lo, hi, sink);
    }

    fn has_features(&self) -> bool {
        self.now.mesh.has_features()
    }

    /// The path relative to the surface: its start carried as the surface point nearest it
    /// moved over the step (exact where the surface near it translates), its end as it is.
    fn crossing(&self, from: &Vec3, to: &Vec3) -> Option<Contact> {
        self.now.mesh.crossing(&self.carried(from), to)
    }

    fn segment_meets(&self, a: &Vec3, b: &Vec3) -> bool {
        self.now.mesh.segment_meets(a, b)
    }

    fn thickness(&self) -> Option<f64> {
        self.now.mesh.thickness()
    }

    fn advance_to(&mut self, t0: f64, t1: f64) {
        if self.now.t == t0 {
            // Steps follow each other: the last end is this start.
            std::mem::swap(&mut self.before, &mut self.now);
        } else if self.before.t != t0 {
            self.before = self.pose(t0);
        }
        self.now = if t1 == t0 {
            self.before.clone()
        } else {
            self.pose(t1)
        };
    }

    fn is_moving(&self) -> bool {
        self.animation.cache.len() > 1
    }

    fn motion_spans(&self) -> Vec<(f64, f64)> {
        self.animation.cache.spans()
    }

    /// A material point is a fixed combination of its triangle's corners, so it moves at
    /// most as far as the farthest of them, whose paths are straight between samples: the
    /// most each corner is from where it started, at the samples within the span and at its
    /// end, over the triangles that start within twice that of the box.
    fn sweep(&self, (t0, t1): (f64, f64), lo: &Vec3, hi: &Vec3) -> f64 {
        let MeshAnimation {
            cache,
            first,
            pieces,
        } = &*self.animation;
        let mut start = Vec::new();
        cache.at(t0, &mut start);
        let mut moved = vec![0.0_f64; start.len()];
        let mut x = Vec::new();
        for t in cache.turns(t0, t1).chain([t1]) {
            cache.at(t, &mut x);
            for ((m, a), b) in moved.iter_mut().zip(&start).zip(&x) {
                *m = m.max((b - a).norm());
            }
        }
        let mut most = 0.0_f64;
        for piece in pieces {
            for tri in &piece.triangles {
                let corners = tri.map(|i| first[piece.vertices[i as usize] as usize] as usize);
                let d = corners.iter().map(|&c| moved[c]).fold(0.0, f64::max);
                if d <= most {
                    continue;
                }
                let (a, b) = corners.iter().fold(
                    (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                    |(a, b), &c| (a.inf(&start[c]), b.sup(&start[c])),
                );
                let near = (0..3).all(|k| a[k] <= hi[k] + 2.0 * d && b[k] >= lo[k] - 2.0 * d);
                if near {
                    most = d;
                }
            }
        }
        most
    }

    fn velocity(&self, p: &Vec3) -> Vec3 {
        let dt = self.now.t - self.before.t;
        if dt <= 0.0 {
            return Vec3::zeros();
        }
        self.travel(&self.now, p) / dt
    }

    fn carried(&self, p: &Vec3) -> Vec3 {
        p + self.travel(&self.before, p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cache::tests::pc2;

    /// A unit square in y = 0 (two triangles) whose cache lifts it by `rise` m a sample over
    /// three samples at 10 fps.
    fn rising(rise: f32) -> DeformingMesh {
        let text = "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 3 2\nf 1 4 3\n";
        let mesh = PolygonMesh::parse(text, Path::new("sq.obj"), 100).unwrap();
        let corners = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
        ];
        let samples: Vec<Vec<[f32; 3]>> = (0..3)
            .map(|k| {
                corners
                    .iter()
                    .map(|c| [c[0], rise * k as f32, c[2]])
                    .collect()
            })
            .collect();
        let cache = VertexCache::parse(
            &pc2(&samples),
            Path::new("sq.pc2"),
            4,
            10.0,
            &Placement::default(),
        )
        .unwrap();
        DeformingMesh::new(
            "mesh sq.obj",
            &mesh,
            &Placement::default(),
            cache,
            Path::new("sq.pc2"),
        )
        .unwrap()
    }

    #[test]
    fn a_rising_sheet_carries_its_points_and_bounds_their_travel() {
        let mut m = rising(0.2);
        let (lo, hi) = (Vec3::new(0.2, -0.1, 0.2), Vec3::new(0.8, 0.1, 0.8));
        // 0.2 m a sample at 10 fps: 2 m/s; from 0.05 s to 0.15 s it rises 0.2 m.
        assert!((m.sweep((0.05, 0.15), &lo, &hi) - 0.2).abs() < 1e-6);
        m.advance_to(0.05, 0.15);
        let p = Vec3::new(0.5, 0.2, 0.5);
        let v = m.velocity(&p);
        assert!((v - Vec3::new(0.0, 2.0, 0.0)).norm() < 1e-5, "{v:?}");
        let c = m.carried(&Vec3::new(0.4, 0.1, 0.6));
        assert!((c - Vec3::new(0.4, 0.3, 0.6)).norm() < 1e-5, "{c:?}");
        // A point that stayed where it was while the sheet rose through it crossed it.
        let hit = m.crossing(&Vec3::new(0.5, 0.12, 0.5), &Vec3::new(0.5, 0.12, 0.5));
        assert!(hit.is_some());
        // Far from the box, nothing moving near it: no travel.
        let far = (Vec3::repeat(10.0), Vec3::repeat(11.0));
        assert_eq!(m.sweep((0.05, 0.15), &far.0, &far.1), 0.0);
        assert_eq!(m.animation().triangles_at(0.2)[0][0].y as f32, 0.4);
    }

    #[test]
    fn corners_the_mesh_welds_must_stay_together() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 0\nf 1 2 3\nf 4 3 2\n";
        let mesh = PolygonMesh::parse(text, Path::new("t.obj"), 100).unwrap();
        let s0 = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 1.0],
            [0.0, 0.0, 0.0],
        ];
        let mut s1 = s0.clone();
        s1[3] = [0.0, 0.5, 0.0];
        let cache = VertexCache::parse(
            &pc2(&[s0, s1]),
            Path::new("t.pc2"),
            4,
            24.0,
            &Placement::default(),
        )
        .unwrap();
        let e = DeformingMesh::new("t", &mesh, &Placement::default(), cache, Path::new("t.pc2"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("vertices 1 and 4") && e.contains("sample 1") && e.contains("tear"),
            "{e}"
        );
    }
}
