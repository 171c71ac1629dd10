//! # hooke-collide: the shapes particles collide with
//!
//! Implementations of [`hooke_core::Collider`] for the colliders of the physics contract
//! (`docs/physics.md` §2):
//!
//! | shape | type | inside when |
//! |---|---|---|
//! | ground `y = h0` | [`Plane::ground`] | `y < h0` |
//! | inclined plane | [`Plane::inclined`] | on the side opposite the body's start |
//! | box interior (jello) | [`BoxInterior`] | a coordinate strictly beyond a face |
//! | analytic cylinder tabletop | [`Cylinder`] | within the disc |
//! | ball | [`Sphere`] | nearer the centre than the radius |
//! | triangle mesh (OBJ) | [`TriMeshCollider`] | inside a closed part, or crossed in a step |
//! | deforming mesh (OBJ + PC2 or an OBJ sequence) | [`DeformingMesh`] | as a mesh, on the cache's positions now |
//!
//! Planes, the box, the cylinder and the ball are closed-form (the contract's formulas as written);
//! meshes use parry3d-f64's BVH, point projection with pseudo-normals and ray casts, and are
//! read with tobj. This is the only crate that names parry3d or tobj, and it never touches
//! velocities: responses belong to the core.
//!
//! ```
//! use hooke_collide::{load_mesh_str, Placement};
//! use hooke_core::{Collider, Vec3};
//! let table = load_mesh_str(&hooke_collide::table::round_table_obj(), "table.obj", &Placement::default()).unwrap();
//! assert!(table.inside(&Vec3::new(0.1, 0.99, 0.0)));   // just under the top face
//! assert!(!table.inside(&Vec3::new(0.1, 1.01, 0.0)));  // just above it
//! ```

#![forbid(unsafe_code)]

mod bounds;
mod box_interior;
mod cache;
mod convert;
mod cylinder;
mod deforming;
mod obj;
mod plane;
mod polygons;
mod sequence;
mod sharp;
mod shells;
mod sphere;
pub mod table;
mod trimesh;

pub use box_interior::{BOX_FACES, BoxInterior};
pub use cache::VertexCache;
pub use cylinder::Cylinder;
pub use deforming::{DeformingMesh, MeshAnimation};
pub use obj::{MeshError, MeshPart, Placement, load_obj, parse_obj};
pub use plane::Plane;
pub use polygons::{Polygon, PolygonMesh};
pub use sequence::{is_sequence, sequence_files};
pub use shells::{closedness_defect, signed_volume};
pub use sphere::Sphere;
pub use trimesh::TriMeshCollider;

use std::path::Path;

/// Reads an OBJ file into a mesh collider: its closed objects are solids, its open ones thin
/// sheets caught by the crossing test.
pub fn load_mesh(path: &Path, placement: &Placement) -> Result<TriMeshCollider, MeshError> {
    let parts = load_obj(path, placement)?;
    TriMeshCollider::new(format!("mesh {}", path.display()), parts, path, false)
}

/// [`load_mesh`] on OBJ text already in memory; `name` is used in messages.
pub fn load_mesh_str(
    text: &str,
    name: &str,
    placement: &Placement,
) -> Result<TriMeshCollider, MeshError> {
    let path = Path::new(name);
    let parts = parse_obj(text, path, placement)?;
    TriMeshCollider::new(format!("mesh {name}"), parts, path, false)
}
