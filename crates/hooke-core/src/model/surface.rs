//! The triangulated surface of a body, which contacts act on (cloth sheets, a jelly's skin).

use std::ops::Range;

/// Cloth contact thickness when a scene gives none: 5 mm, within the few millimetres cloth
/// simulators use (Blender's default collision distance is 15 mm), and larger than the
/// distance any built-in scene's particles travel in one step, so a proximity is seen before
/// a crossing.
pub const DEFAULT_CLOTH_THICKNESS: f64 = 0.005;

/// Friction between two surfaces when a scene gives none (cloth on cloth).
pub const DEFAULT_SURFACE_FRICTION: f64 = 0.3;

/// One body's surface: its triangles, how far other things keep from it, and whether it
/// collides with itself.
///
/// A surface with zero thickness takes part in no contact beyond the per-particle
/// collider tests (the jello worlds), so adding one changes nothing.
///
/// ```
/// use hooke_core::Surface;
/// // Two triangles of a unit square, particles 0..4.
/// let s = Surface {
///     particles: 0..4,
///     triangles: vec![[0, 1, 2], [0, 2, 3]],
///     thickness: 0.005,
///     self_collision: true,
///     friction: 0.3,
/// };
/// assert_eq!(s.edges(), vec![[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// The body's particles (a contiguous range of the simulation's).
    pub particles: Range<usize>,
    /// Triangles as indices into the simulation's particles, all within `particles`.
    pub triangles: Vec<[u32; 3]>,
    /// Contact thickness in metres: colliders' surfaces and other triangles are kept this
    /// far from its particles and triangles. Zero disables its contacts.
    pub thickness: f64,
    /// Whether its own triangles collide with each other.
    pub self_collision: bool,
    /// Coulomb friction coefficient against other surfaces (and itself).
    pub friction: f64,
}

impl Surface {
    /// The distinct edges of its triangles, each `[low, high]`, sorted.
    pub fn edges(&self) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = self
            .triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .map(|[a, b]| [a.min(b), a.max(b)])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// Whether its contacts are on (a positive thickness).
    pub fn is_active(&self) -> bool {
        self.thickness > 0.0
    }
}
