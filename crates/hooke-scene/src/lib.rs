//! # hooke-scene: what to simulate
//!
//! * the TOML scene format ([`spec`]), read with line-numbered errors by [`parse_scene`] and
//!   [`load_scene`], written by [`to_toml`];
//! * generators for chains, cloth grids and jelly lattices with structural, shear and bend
//!   springs ([`generators`]);
//! * the nine built-in scenes ([`builtin`]): the course's five, `cloth-pile`, `flag`, the
//!   material `tablecloth` and the moving `puck-sweep`;
//! * building a ready-to-step [`Scene`] from a description ([`SceneSpec::build`]).
//!
//! ```
//! let spec = hooke_scene::builtin::builtin("chain").unwrap();
//! let text = hooke_scene::to_toml(&spec);
//! let again = hooke_scene::parse_scene(&text, "chain.toml").unwrap();
//! assert_eq!(spec, again);
//! let mut scene = again.build(std::path::Path::new(".")).unwrap();
//! scene.simulation.advance(10).unwrap();
//! ```

#![forbid(unsafe_code)]

mod air;
mod body;
mod build;
pub mod builtin;
pub mod collider_mesh;
mod colliders;
mod contact_surface;
mod edit;
mod error;
pub mod example_meshes;
pub mod footprint;
pub mod generators;
mod joined;
mod limits;
pub mod material;
mod overlaps;
mod overrides;
mod ranges;
mod scene;
mod scene_toml;
pub mod skin;
pub mod spec;
pub mod surface;
mod suspicious;
mod tagged;
pub mod workload;
pub mod world;

pub use body::mesh::solid::enclosed_volume;
pub use colliders::{BUILTIN_MESHES, mesh_text};
pub use error::BuildError;
pub use limits::{MAX_PARTICLES, MAX_STEPS};
pub use overrides::{Overrides, TableOverride};
pub use scene::{Body, ColliderGeometry, ColliderPose, Scene, Topology};
pub use scene_toml::{SceneError, load_scene, parse_scene, to_toml};
pub use skin::{Skin, SkinFace, SkinVertex};
pub use spec::SceneSpec;
