//! The scene file format: what a `.toml` scene says, as serde types.
//!
//! Every table refuses unknown keys, and values are checked while they are read (positive
//! step sizes and masses, finite numbers, known names), so a mistake is reported with the
//! file's line and column. Units are SI; scenes are +Y up. See `assets/scenes/*.toml` for one
//! complete example per built-in scene.

use hooke_core::{Integrator, SpringKind, Vec3};
use nalgebra::Rotation3;
use serde::{Deserialize, Serialize};

mod collider;

pub use collider::{ColliderShapeSpec, ColliderSpec, KeySpec, MotionSpec, ResponseSpec};

/// Defines a checked `f64`: a private field, so a value exists only once it passed `$ok`.
macro_rules! checked_number {
    ($(#[$doc:meta])* $name:ident, $expected:literal, |$x:ident| $ok:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, PartialOrd, Serialize, Deserialize)]
        #[serde(try_from = "f64", into = "f64")]
        pub struct $name(f64);

        // `Range::contains` is not a `const fn`; `of` is.
        #[allow(clippy::manual_range_contains)]
        impl $name {
            #[doc = concat!("`x` when it is ", $expected, "; otherwise what was expected and found.")]
            pub fn new($x: f64) -> Result<Self, String> {
                if $ok {
                    Ok(Self($x))
                } else {
                    Err(format!(
                        concat!("expected ", $expected, ", found {}"),
                        hooke_core::Num($x)
                    ))
                }
            }

            #[doc = concat!("`x`, which must be ", $expected, ": for constants and values")]
            /// already checked; use `new` for anything read or computed.
            ///
            /// # Panics
            /// When `x` is out of range (at compile time in a `const`).
            pub const fn of($x: f64) -> Self {
                assert!($ok, concat!("expected ", $expected));
                Self($x)
            }

            /// The value.
            pub const fn get(self) -> f64 {
                self.0
            }
        }

        impl TryFrom<f64> for $name {
            type Error = String;
            fn try_from(x: f64) -> Result<Self, String> {
                Self::new(x)
            }
        }

        impl From<$name> for f64 {
            fn from(x: $name) -> f64 {
                x.0
            }
        }
    };
}

checked_number!(
    /// A finite `f64`, refused at read time when NaN or infinite.
    ///
    /// ```
    /// use hooke_scene::spec::Finite;
    /// assert_eq!(Finite::new(1.5).map(Finite::get), Ok(1.5));
    /// assert_eq!(Finite::new(f64::NAN).unwrap_err(), "expected a finite number, found NaN");
    /// ```
    Finite,
    "a finite number",
    |x| x.is_finite()
);
checked_number!(
    /// A finite `f64` greater than zero.
    Positive,
    "a finite number > 0",
    |x| x.is_finite() && x > 0.0
);
checked_number!(
    /// A finite `f64` at least zero.
    NonNegative,
    "a finite number >= 0",
    |x| x.is_finite() && x >= 0.0
);
checked_number!(
    /// A finite `f64` in `[0, 1]`.
    Fraction,
    "a number in [0, 1]",
    |x| x >= 0.0 && x <= 1.0
);

/// An integrator name, checked at read time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct IntegratorName(pub Integrator);

impl TryFrom<String> for IntegratorName {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        s.parse()
            .map(Self)
            .map_err(|e: hooke_core::UnknownIntegrator| e.to_string())
    }
}

impl From<IntegratorName> for String {
    fn from(i: IntegratorName) -> String {
        i.0.name().to_string()
    }
}

/// A whole scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Short name, used in file names and messages.
    pub name: String,
    /// One sentence on what the scene shows.
    #[serde(default)]
    pub description: String,
    /// Time stepping and global forces.
    pub simulation: SimulationSpec,
    /// The bodies, in order; particle indices run through them in this order.
    #[serde(default, rename = "body")]
    pub bodies: Vec<BodySpec>,
    /// The colliders.
    #[serde(default, rename = "collider")]
    pub colliders: Vec<ColliderSpec>,
    /// An optional force field on a grid over `[-2, 2]^3` (jello worlds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_field: Option<ForceFieldSpec>,
}

/// `[simulation]`: integrator, step size, length of the run, frame cadence, global forces.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// `euler`, `symplectic`, `midpoint` or `rk4`.
    pub integrator: IntegratorName,
    /// Step size in seconds.
    pub dt: Positive,
    /// Length of the run in seconds (rounded to whole steps); give this or `steps`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration: Option<Positive>,
    /// Length of the run in steps; give this or `duration`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<u64>,
    /// A frame every this many steps.
    pub every: u64,
    /// Gravitational acceleration in m/s² (default `[0, -9.81, 0]`).
    #[serde(default = "default_gravity")]
    pub gravity: [Finite; 3],
    /// Linear drag on every particle in N·s/m per particle, the course's convention
    /// (default 0): a body's drag then depends on how many particles it has, so a body
    /// given as a `material` takes `mass_drag` instead.
    #[serde(default = "zero", skip_serializing_if = "is_zero")]
    pub drag: NonNegative,
    /// Linear drag in N·s/m per kilogram of particle (1/s; force `-mass_drag m v`), the
    /// same for a body at any resolution (default 0).
    #[serde(default = "zero", skip_serializing_if = "is_zero")]
    pub mass_drag: NonNegative,
    /// The large steps' stopping tolerance (`vbd`, `newton`), m/s: a step ends when its
    /// last update moved no free particle by more than this times `dt` (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<Positive>,
    /// The large steps' iteration budget per step (default: `vbd` 24, `newton` 100).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iterations: Option<u64>,
    /// The air that bodies with a surface (grids, lattices) move in: drag and lift per
    /// triangle (docs/physics.md §1, "Air"). Absent: vacuum.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub air: Option<AirSpec>,
}

/// `[simulation] air = { density = 1.225, wind = [wx, wy, wz], gust = { … } }`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AirSpec {
    /// Density in kg/m³ (default 1.225, sea level).
    #[serde(default = "sea_level")]
    pub density: Positive,
    /// The steady wind velocity in m/s (default still air).
    #[serde(default = "still")]
    pub wind: [Finite; 3],
    /// A periodic gust on top of the wind.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust: Option<GustSpec>,
}

fn sea_level() -> Positive {
    Positive::of(hooke_core::forces::air::SEA_LEVEL_DENSITY)
}

fn still() -> [Finite; 3] {
    [Finite::of(0.0); 3]
}

/// `gust = { amplitude = [ax, ay, az], period = T }`: the wind plus
/// `amplitude · sin(2π t / T)`, a smooth function of time with no random state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GustSpec {
    /// The largest change of the wind, m/s.
    pub amplitude: [Finite; 3],
    /// Seconds from one gust to the next.
    pub period: Positive,
}

/// A body's aerodynamic coefficients: `aero = { drag = C_d, lift = C_l }`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AeroSpec {
    /// Drag coefficient (default 1, a flat plate face-on).
    #[serde(default = "unit_drag")]
    pub drag: NonNegative,
    /// Lift coefficient (default 0).
    #[serde(default = "no_lift")]
    pub lift: Finite,
}

impl Default for AeroSpec {
    fn default() -> Self {
        Self {
            drag: unit_drag(),
            lift: no_lift(),
        }
    }
}

fn unit_drag() -> NonNegative {
    NonNegative::of(1.0)
}

fn no_lift() -> Finite {
    Finite::of(0.0)
}

fn default_gravity() -> [Finite; 3] {
    [Finite(0.0), Finite(-9.81), Finite(0.0)]
}

fn zero() -> NonNegative {
    NonNegative(0.0)
}

fn is_zero(x: &NonNegative) -> bool {
    x.0 == 0.0
}

/// `[[body]]`: a set of particles made by one generator, and their springs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Name of the body.
    pub name: String,
    /// Mass of every particle in kg (not with `material`, which gives the masses).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<Positive>,
    /// Where the generator's local origin goes, metres.
    #[serde(default = "origin")]
    pub origin: [Finite; 3],
    /// Rotation of the generated shape about its local origin: degrees about x, then y, then z.
    #[serde(default = "origin")]
    pub rotate: [Finite; 3],
    /// Initial velocity of every particle, m/s.
    #[serde(default = "origin")]
    pub velocity: [Finite; 3],
    /// Pinned particles: indices within the body (for a mesh, the file's vertex indices
    /// from 0), or a region or group (see [`Pins`]).
    #[serde(default, skip_serializing_if = "Pins::is_empty")]
    pub pins: Pins,
    /// Explicit initial positions overriding the generated ones (world coordinates); rest
    /// lengths still come from the generated, undeformed shape.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub positions: Option<Vec<[Finite; 3]>>,
    /// Explicit initial velocities overriding `velocity`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocities: Option<Vec<[Finite; 3]>>,
    /// The generator: `chain`, `grid`, `lattice` or `points`.
    pub shape: ShapeSpec,
    /// Springs by topology and explicit pairs (not with `material`).
    #[serde(default, skip_serializing_if = "SpringsSpec::is_empty")]
    pub springs: SpringsSpec,
    /// Keys that move the body's pinned particles rigidly about their centroid at the start
    /// (docs/physics.md §1.2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pin_motion: Option<MotionSpec>,
    /// A cloth's material in SI units, from which a grid's masses and springs are derived
    /// for its spacing (docs/physics.md §1.1); instead of `mass` and `springs`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<MaterialSpec>,
    /// Contact thickness in metres: colliders and other surfaces are kept this far from the
    /// body's particles and triangles (`docs/physics.md` §3). Default: 5 mm for a `grid`
    /// (cloth), capped at a quarter of its spacing; 0 for other shapes, whose contacts are
    /// then exactly the per-particle tests of docs/physics.md §3.3. Chains and points have no surface.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<NonNegative>,
    /// Whether the body's surface collides with itself (default: on when it has a
    /// thickness). Collisions with other bodies' surfaces are on whenever either has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub self_collision: Option<bool>,
    /// Coulomb friction coefficient of the surface against surfaces (default 0.3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<NonNegative>,
    /// Drag and lift coefficients for the air of `[simulation] air` (default drag 1, lift 0;
    /// only bodies with a surface feel air).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aero: Option<AeroSpec>,
}

/// `pins`: which particles are held.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a list of indices, or one of { box = [[x0, y0, z0], [x1, y1, z1]] }, \
                 { sphere = { center = [x, y, z], radius = r } }, { group = \"NAME\" }"
)]
pub enum Pins {
    /// Particle indices within the body; for a mesh, vertex indices in the file's order
    /// from 0.
    Indices(Vec<usize>),
    /// Every particle in a region (in the body's own coordinates; a mesh's are the file's,
    /// before `scale`), or every vertex of an OBJ group's faces.
    Region(PinRegion),
}

impl Default for Pins {
    fn default() -> Self {
        Self::Indices(Vec::new())
    }
}

impl From<Vec<usize>> for Pins {
    fn from(v: Vec<usize>) -> Self {
        Self::Indices(v)
    }
}

impl Pins {
    /// Whether no pin is asked for.
    pub fn is_empty(&self) -> bool {
        matches!(self, Self::Indices(v) if v.is_empty())
    }

    /// The indices, when pins are given as indices.
    pub fn indices(&self) -> &[usize] {
        match self {
            Self::Indices(v) => v,
            Self::Region(_) => &[],
        }
    }
}

/// `pins = { box = … }`, `{ sphere = … }` or `{ group = … }`: exactly one of them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinRegion {
    /// A box by its lowest and highest corners (each coordinate of the first at most the
    /// second's).
    #[serde(rename = "box", default, skip_serializing_if = "Option::is_none")]
    pub aabb: Option<[[Finite; 3]; 2]>,
    /// A ball.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sphere: Option<PinSphere>,
    /// The name of an OBJ group (`g`) or object (`o`) of a mesh body.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
}

/// A ball of pins.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinSphere {
    /// Its centre.
    pub center: [Finite; 3],
    /// Its radius, metres: above zero (checked when the body is built, so that the error
    /// names the key rather than the whole `pins` table).
    pub radius: Finite,
}

fn origin() -> [Finite; 3] {
    [Finite(0.0); 3]
}

/// How a body's particles are laid out (in its local frame, before `rotate` and `origin`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "kebab-case",
    try_from = "crate::tagged::ShapeTable"
)]
pub enum ShapeSpec {
    /// `count` particles along local +x, `spacing` apart, the first at the origin.
    Chain {
        /// Number of particles.
        count: usize,
        /// Distance between neighbours, metres.
        spacing: Positive,
    },
    /// A cloth: `size[0] × size[1]` particles in the local x-z plane; particle `(i, j)` at
    /// `(i h, 0, j h)`, index `i size[1] + j`.
    Grid {
        /// Particles along x and z.
        size: [usize; 2],
        /// Spacing `h`, metres.
        spacing: Positive,
    },
    /// A jelly block: `size[0] × size[1] × size[2]` particles; `(i, j, k)` at `(i h, j h, k h)`,
    /// index `(i size[1] + j) size[2] + k`.
    Lattice {
        /// Particles along x, y and z.
        size: [usize; 3],
        /// Spacing `h`, metres.
        spacing: Positive,
    },
    /// Explicit particles in the local frame.
    Points {
        /// Positions, metres.
        positions: Vec<[Finite; 3]>,
    },
    /// A cloth from a surface mesh (docs/physics.md §1.1): one particle per vertex the faces
    /// use, springs on its edges and quads' diagonals, bending across its interior edges.
    Mesh {
        /// The OBJ file, relative to the scene file, or `builtin:NAME`.
        path: String,
        /// Per-axis scale of the file's coordinates.
        scale: [Positive; 3],
        /// Merges vertices closer than this, metres in the file's coordinates (a triangle
        /// soup); none by default: vertices are the file's.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weld: Option<Positive>,
    },
    /// A jelly filling a closed mesh with a lattice of `spacing`; the mesh's surface is
    /// carried by the lattice, each vertex trilinearly in its cell.
    Solid {
        /// The OBJ file, relative to the scene file, or `builtin:NAME`.
        path: String,
        /// Per-axis scale of the file's coordinates.
        scale: [Positive; 3],
        /// The lattice's spacing, metres.
        spacing: Positive,
    },
}

impl ShapeSpec {
    /// The mesh file a `mesh` or `solid` body reads.
    pub fn mesh_path(&self) -> Option<&str> {
        match self {
            Self::Mesh { path, .. } | Self::Solid { path, .. } => Some(path),
            _ => None,
        }
    }
}

/// Stiffness and damping of a family of springs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringParams {
    /// Stiffness in N/m.
    pub ks: NonNegative,
    /// Damping along the spring in N·s/m.
    pub kd: NonNegative,
}

/// `[body.springs]`: which springs the generator makes, plus explicit ones.
///
/// Structural springs join axis neighbours; shear springs the face diagonals of a grid, and
/// the face and body diagonals of a lattice; bend springs axis neighbours two apart. Rest
/// lengths are the distances in the generated (undeformed) shape.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringsSpec {
    /// Springs between axis neighbours.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub structural: Option<SpringParams>,
    /// Springs along diagonals.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear: Option<SpringParams>,
    /// Springs between axis neighbours two apart.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bend: Option<SpringParams>,
    /// Explicit springs between particles of this body.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pairs: Vec<PairSpec>,
}

/// `[body.material]`: a cloth in SI units; any key overrides its `preset`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// A named material (`cotton`, `silk`, `wool`, `denim`) whose values the other keys
    /// override.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Areal density, kg/m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<Positive>,
    /// Membrane stiffness per unit width along the grid's lines, N/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stretch: Option<Positive>,
    /// Membrane shear stiffness per unit width (the diagonal springs), N/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear: Option<NonNegative>,
    /// Bending rigidity per unit width `B`, N·m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending: Option<NonNegative>,
    /// Stiffness-proportional damping, seconds: each membrane spring's `kd` is this times
    /// its `ks`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<NonNegative>,
}

/// One explicit spring.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairSpec {
    /// First particle (index within the body).
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Stiffness in N/m.
    pub ks: NonNegative,
    /// Damping in N·s/m.
    pub kd: NonNegative,
    /// Rest length in metres (default: the initial distance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rest: Option<NonNegative>,
}

/// `[force_field]`: `resolution³` force vectors in newtons, in file order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceFieldSpec {
    /// Nodes per axis.
    pub resolution: usize,
    /// The vectors, node `(a, b, c)` at index `a r² + b r + c`.
    pub values: Vec<[Finite; 3]>,
}

impl SpringsSpec {
    /// Whether no spring is given.
    pub fn is_empty(&self) -> bool {
        self.structural.is_none()
            && self.shear.is_none()
            && self.bend.is_none()
            && self.pairs.is_empty()
    }

    /// The parameters of one family.
    pub fn params(&self, kind: SpringKind) -> Option<SpringParams> {
        match kind {
            SpringKind::Structural => self.structural,
            SpringKind::Shear => self.shear,
            SpringKind::Bend => self.bend,
            SpringKind::Other => None,
        }
    }
}

/// A described vector as the core's.
pub(crate) fn vec3(v: &[Finite; 3]) -> Vec3 {
    Vec3::new(v[0].get(), v[1].get(), v[2].get())
}

/// A rotation by Euler angles in degrees (x, y, z).
pub(crate) fn rotation(degrees: &[Finite; 3]) -> Rotation3<f64> {
    let r = vec3(degrees).map(f64::to_radians);
    Rotation3::from_euler_angles(r.x, r.y, r.z)
}
