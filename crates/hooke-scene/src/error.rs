//! Why a scene description cannot be simulated.

use hooke_collide::MeshError;

/// Why a scene description cannot be simulated.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// A value is inconsistent with the rest of the scene.
    #[error("{key}: {message}")]
    Invalid {
        /// Where in the scene, e.g. `body[1].pins[3]`.
        key: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A mesh could not be loaded (the mesh error follows in the error's chain).
    #[error("{key}")]
    Mesh {
        /// Where in the scene.
        key: String,
        /// The mesh error (names the file and, where it can, the line).
        source: MeshError,
    },
}

pub(crate) fn invalid(key: impl Into<String>, message: impl Into<String>) -> BuildError {
    BuildError::Invalid {
        key: key.into(),
        message: message.into(),
    }
}
