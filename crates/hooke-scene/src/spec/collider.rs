//! Colliders and motions in a scene file: `[[collider]]`, its shape and response, and the
//! `motion` a collider or a body's pins follow (keys, or a vertex cache).

use super::{Finite, Fraction, NonNegative, Positive, vec3};
use hooke_core::Vec3;
use serde::{Deserialize, Serialize};

/// `[[collider]]`: a shape and the response it triggers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColliderSpec {
    /// The shape.
    pub shape: ColliderShapeSpec,
    /// What it does to particles that violate it.
    pub response: ResponseSpec,
    /// Keys that move a mesh, box, cylinder or sphere rigidly about its placed origin or centre
    /// (docs/physics.md §2.1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
}

/// A collider's geometry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "kebab-case",
    try_from = "crate::tagged::ColliderShapeTable"
)]
pub enum ColliderShapeSpec {
    /// The plane `y = height`, solid below.
    Ground {
        /// Height in metres.
        height: Finite,
    },
    /// The plane `a x + b y + c z + d = 0`; the side holding the particles' initial centroid
    /// is free.
    Plane {
        /// `[a, b, c, d]`.
        coefficients: [Finite; 4],
    },
    /// The inside of an axis-aligned box is free; outside is solid.
    Box {
        /// Lower corner, metres.
        min: [Finite; 3],
        /// Upper corner, metres.
        max: [Finite; 3],
    },
    /// The analytic cylinder tabletop.
    Cylinder {
        /// Centre of the top face, metres.
        center: [Finite; 3],
        /// Radius, metres.
        radius: Positive,
        /// Thickness, metres.
        thickness: Positive,
    },
    /// A solid ball.
    Sphere {
        /// Centre, metres.
        center: [Finite; 3],
        /// Radius, metres.
        radius: Positive,
    },
    /// A triangle mesh from an OBJ file. `path` is relative to the scene file; `builtin:NAME`
    /// names a mesh shipped inside Hooke (`builtin:table.obj`, `builtin:square-table.obj`, and `builtin:ball.obj`, a ball of radius 1 m to scale).
    Mesh {
        /// The OBJ file.
        path: String,
        /// Translation, metres (default zero).
        translate: [Finite; 3],
        /// Rotation in degrees about x, then y, then z (default zero).
        rotate: [Finite; 3],
        /// Scale per axis (default one).
        scale: [Positive; 3],
    },
}

/// A collision response (docs/physics.md §3.3).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "kebab-case",
    try_from = "crate::tagged::ResponseTable"
)]
pub enum ResponseSpec {
    /// Penalty spring `kc δ n - dc (v·n) n`.
    Penalty {
        /// Stiffness in N/m.
        kc: NonNegative,
        /// Damping in N·s/m.
        dc: NonNegative,
    },
    /// Projection and restitution after each step.
    Restitution {
        /// Coefficient of restitution.
        cr: Fraction,
        /// Coulomb's coefficient of friction μ (default 0: frictionless).
        friction: NonNegative,
    },
    /// Projection and a full stop after each step.
    Stick,
}

/// `[body.pin_motion]` and a collider's `motion`: rigid keys,
/// `keys = [{ t, translate, rotate }, …]`, or, for a mesh collider, a vertex animation,
/// `cache = "arm.pc2"` (PC2, a point per vertex of the mesh in the file's order) with
/// `fps = 24.0`, its frames per second.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// The keys, in increasing time.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub keys: Vec<KeySpec>,
    /// A PC2 vertex cache animating a mesh collider, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cache: Option<String>,
    /// The cache's frames per second: sample `k` is at `k · sampling / fps` seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fps: Option<Positive>,
}

/// One key of a motion.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeySpec {
    /// Seconds.
    pub t: Finite,
    /// Metres, relative to the start.
    pub translate: [Finite; 3],
    /// Degrees about x, then y, then z, relative to the start (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate: Option<[Finite; 3]>,
}

impl ColliderShapeSpec {
    /// The point a collider turns about when it moves: a mesh's placed origin
    /// (`translate`), the centre of a box, a cylinder or a sphere; `None` for a ground or a
    /// plane, which cannot move.
    pub fn pivot(&self) -> Option<Vec3> {
        match self {
            Self::Mesh { translate, .. } => Some(vec3(translate)),
            Self::Box { min, max } => Some((vec3(min) + vec3(max)) / 2.0),
            Self::Cylinder { center, .. } | Self::Sphere { center, .. } => Some(vec3(center)),
            Self::Ground { .. } | Self::Plane { .. } => None,
        }
    }
}

impl MotionSpec {
    /// A motion by `keys` (no cache).
    pub fn of_keys(keys: Vec<KeySpec>) -> Self {
        Self {
            keys,
            cache: None,
            fps: None,
        }
    }

    /// The keys as the core's, checked (at least one, times increasing).
    pub fn keyframes(&self) -> Result<hooke_core::Keyframes, hooke_core::KeyError> {
        hooke_core::Keyframes::new(
            self.keys
                .iter()
                .map(|k| hooke_core::Key {
                    t: k.t.get(),
                    translate: vec3(&k.translate),
                    rotate: k.rotate.as_ref().map_or(Vec3::zeros(), vec3),
                })
                .collect(),
        )
    }
}
