//! # hooke-scene: what to simulate
//!
//! * the TOML scene format ([`spec`]), read with line-numbered errors by [`parse_scene`] and
//!   [`load_scene`], written by [`to_toml`];
//! * generators for chains, cloth grids and jelly lattices with structural, shear and bend
//!   springs ([`generators`]);
//! * the five built-in scenes ([`builtin`]);
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

mod build;
pub mod builtin;
pub mod collider_mesh;
pub mod generators;
pub mod spec;
pub mod surface;
pub mod workload;
pub mod world;

pub use build::{
    BUILTIN_MESHES, Body, BuildError, ColliderGeometry, MAX_PARTICLES, Overrides, Scene, Topology,
};
pub use spec::SceneSpec;

use std::path::{Path, PathBuf};

/// Why a scene file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read scene {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The text is not a valid scene; the message holds the line, the column and what was
    /// expected.
    #[error("{path}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// toml's message, with line and column.
        message: String,
    },
}

/// Parses scene text; `name` names it in errors.
pub fn parse_scene(text: &str, name: impl AsRef<Path>) -> Result<SceneSpec, SceneError> {
    toml::from_str(text).map_err(|e| SceneError::Syntax {
        path: name.as_ref().to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })
}

/// Reads a scene file.
pub fn load_scene(path: &Path) -> Result<SceneSpec, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_scene(&text, path)
}

/// The scene as TOML text, with a header naming it; [`parse_scene`] reads it back equal.
pub fn to_toml(spec: &SceneSpec) -> String {
    let body = toml::to_string(spec).expect("scene specs always serialise");
    format!(
        "# Hooke scene '{}': {}\n# Format: see crates/hooke-scene/src/spec.rs and the README.\n\n{body}",
        spec.name, spec.description
    )
}
