//! What building a description gives: the scene ready to step, its bodies and the
//! geometry of its colliders for drawing.

use crate::skin::Skin;
use crate::spec::SceneSpec;
use hooke_collide::{BoxInterior, Cylinder, Sphere};
use hooke_core::{Simulation, Vec3};
use std::ops::Range;
use std::sync::Arc;

/// How a body's particles are arranged, for drawing surfaces and picking subsets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Topology {
    /// A chain of particles.
    Chain,
    /// A cloth grid `[nx, nz]`.
    Grid([usize; 2]),
    /// A jelly lattice `[nx, ny, nz]`.
    Lattice([usize; 3]),
    /// Unstructured points.
    Points,
    /// A cloth made from a surface mesh (its faces are in the body's [`Skin`]).
    Mesh,
    /// A lattice filling a closed mesh, which it carries as its [`Skin`].
    Solid,
}

/// A body of a built scene: its name, where its particles are, how they are arranged.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name from the scene file.
    pub name: String,
    /// Its particles' indices in the simulation.
    pub range: Range<usize>,
    /// Arrangement.
    pub topology: Topology,
    /// Surface triangles as simulation particle indices (empty for chains and points).
    pub triangles: Vec<[u32; 3]>,
    /// Contact thickness of the surface, metres (zero: bare per-particle contacts, docs/physics.md §3.3).
    pub thickness: f64,
    /// For a body made from a mesh, the user's vertices and faces, which drawing and every
    /// export show in place of the particles.
    pub skin: Option<Arc<Skin>>,
}

impl Body {
    /// How many vertices the body shows: its mesh's, or its particles.
    pub fn vertex_count(&self) -> usize {
        self.skin
            .as_ref()
            .map_or(self.range.len(), |s| s.vertices.len())
    }

    /// The positions of the vertices the body shows, given every particle's `x`, into `out`:
    /// its mesh's vertices in the file's order, or its particles.
    pub fn vertices(&self, x: &[Vec3], out: &mut Vec<Vec3>) {
        match &self.skin {
            Some(skin) => skin.positions(x, out),
            None => {
                out.clear();
                out.extend_from_slice(&x[self.range.clone()]);
            }
        }
    }

    /// The velocities of the vertices the body shows, given every particle's `v`.
    pub fn vertex_velocities(&self, v: &[Vec3], out: &mut Vec<Vec3>) {
        match &self.skin {
            Some(skin) => {
                out.clear();
                out.extend(skin.vertices.iter().map(|s| s.velocity(v)));
            }
            None => {
                out.clear();
                out.extend_from_slice(&v[self.range.clone()]);
            }
        }
    }

    /// The faces the body shows, as polygons of indices into [`Body::vertices`]: its
    /// mesh's faces as written (quads stay quads), or its surface triangles.
    pub fn faces(&self) -> Vec<Vec<u32>> {
        match &self.skin {
            Some(skin) => skin.faces.iter().map(|f| f.corners.clone()).collect(),
            None => {
                let s = self.range.start as u32;
                self.triangles
                    .iter()
                    .map(|t| t.iter().map(|&i| i - s).collect())
                    .collect()
            }
        }
    }

    /// [`Body::faces`] as triangles (polygons as fans): what is drawn and what formats of
    /// triangles only take.
    pub fn face_triangles(&self) -> Vec<[u32; 3]> {
        match &self.skin {
            Some(skin) => skin.triangles(),
            None => {
                let s = self.range.start as u32;
                self.triangles.iter().map(|t| t.map(|i| i - s)).collect()
            }
        }
    }
}

/// The geometry of a collider, for drawing.
#[derive(Clone, Debug, PartialEq)]
pub enum ColliderGeometry {
    /// The ground plane at this height.
    Ground(f64),
    /// An inclined plane `[a, b, c, d]`.
    Plane([f64; 4]),
    /// The free box interior.
    Box(BoxInterior),
    /// An analytic cylinder tabletop.
    Cylinder(Cylinder),
    /// A solid ball.
    Sphere(Sphere),
    /// A triangle mesh, as world-space triangles.
    Mesh(Vec<[Vec3; 3]>),
}

/// A scene ready to run: the simulation at step 0 and what is needed to run and draw it.
#[derive(Debug)]
pub struct Scene {
    /// The description it was built from.
    pub spec: SceneSpec,
    /// The simulation at step 0.
    pub simulation: Simulation,
    /// Steps in a full run.
    pub steps: u64,
    /// A frame every this many steps.
    pub every: u64,
    /// The bodies.
    pub bodies: Vec<Body>,
    /// Collider geometry, in the order of the scene file (a deforming mesh as it is at the
    /// start).
    pub colliders: Vec<ColliderGeometry>,
    /// Per collider, in the same order, the vertex animation of a mesh its cache deforms
    /// (`motion = { cache, fps }`), for drawing it where it is: see
    /// [`Scene::collider_triangles_at`].
    pub animations: Vec<Option<std::sync::Arc<hooke_collide::MeshAnimation>>>,
    /// The particles moved out of velocity-level colliders before the first step, per
    /// collider (see [`hooke_core::Simulation::push_out_start`]); said as warnings.
    pub pushed_out: Vec<hooke_core::PushedOut>,
    /// What building did to the bodies that the user should hear of (a mesh's dropped
    /// faces or vertices), one line each; said with [`Scene::warnings`].
    pub build_warnings: Vec<String>,
}

/// Where a moving collider is at some time: `x ↦ pivot + translate + R (x − pivot)`, with
/// `R` the rotation by `rotate` (degrees about x, then y, then z; docs/physics.md §2.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColliderPose {
    /// The point it turns about, metres.
    pub pivot: Vec3,
    /// Its translation from where the scene placed it, metres.
    pub translate: Vec3,
    /// Its rotation, degrees about x, then y, then z.
    pub rotate: Vec3,
    rotation: nalgebra::Rotation3<f64>,
}

impl ColliderPose {
    /// Where the point `p` of the collider as placed in the scene is now.
    pub fn place(&self, p: &Vec3) -> Vec3 {
        self.pivot + self.translate + self.rotation * (p - self.pivot)
    }
}

impl Scene {
    /// The triangles of collider `k` at time `t` when a cache deforms it, or `None`.
    pub fn collider_triangles_at(&self, k: usize, t: f64) -> Option<Vec<[Vec3; 3]>> {
        Some(self.animations.get(k)?.as_ref()?.triangles_at(t))
    }

    /// The pose of collider `k` at time `t` (seconds), or `None` when it does not move.
    pub fn collider_pose(&self, k: usize, t: f64) -> Option<ColliderPose> {
        let spec = self.spec.colliders.get(k)?;
        let keys = spec.motion.as_ref()?.keyframes().ok()?;
        let pivot = spec.shape.pivot()?;
        let (translate, rotate) = keys.at(t);
        let (rotation, _) = keys.pose(t);
        Some(ColliderPose {
            pivot,
            translate,
            rotate,
            rotation,
        })
    }

    /// Collider `k`'s pose at each of its keys (none when it does not move): its path,
    /// for framing a picture that shows it wherever it goes.
    pub fn collider_key_poses(&self, k: usize) -> Vec<ColliderPose> {
        let keys = self
            .spec
            .colliders
            .get(k)
            .and_then(|c| c.motion.as_ref())
            .map_or(&[][..], |m| &m.keys[..]);
        keys.iter()
            .filter_map(|key| self.collider_pose(k, key.t.get()))
            .collect()
    }

    /// Whether some collider moves.
    pub fn has_moving_colliders(&self) -> bool {
        self.spec.colliders.iter().any(|c| c.motion.is_some())
    }
}
