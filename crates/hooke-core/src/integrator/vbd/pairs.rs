//! Contact pairs between a body's surfaces and a collider's features: which particles
//! feel them, and their closest points at any positions (docs/physics.md §4.1).

use crate::contact::proximity::{point_triangle, segment_segment};
use crate::particles::Vec3;

/// What a pair's two sides are.
#[derive(Clone, Copy, Debug)]
pub(in crate::integrator) enum Sides {
    /// Particle `ids[0]` against triangle `ids[1..4]`, which owns the features marked in
    /// its mask (see `Topology::owns` in `topology.rs`).
    PointTriangle(u8),
    /// Edge `ids[0..2]` against edge `ids[2..4]`.
    EdgeEdge,
    /// Triangle `ids[0..3]` against the point of a collider's sharp feature nearest it at
    /// the detection (the feature's tangent, as [`Plane`] is the faces'), and how far that
    /// point moves over the step (zero unless the collider moves).
    Feature(Vec3, Vec3),
}

/// A contact between two primitives, felt by the particles in `ids`.
#[derive(Clone, Copy, Debug)]
pub(in crate::integrator) struct Pair {
    pub(in crate::integrator) sides: Sides,
    pub(in crate::integrator) ids: [u32; 4],
    /// The gap kept, metres.
    pub(in crate::integrator) h: f64,
    /// Normal stiffness, N/m.
    pub(in crate::integrator) k: f64,
    /// Coulomb coefficient (infinite: stick; zero: none).
    pub(in crate::integrator) mu: f64,
}

/// The closest points of a pair at `x`: weights `w` on its particles such that
/// `Σ w_k x_k - anchor` is the gap vector, and whether the pair is the one that counts
/// that contact. A point nearest a triangle's edge or corner is as near every triangle
/// sharing it, and two edges nearest at an end are a point against a triangle: such a
/// contact counts once (the owning triangle's, the point–triangle pair's), so that a
/// particle over a fold of a mesh does not feel it six times.
pub(in crate::integrator) fn stencil(pair: &Pair, x: &[Vec3]) -> ([f64; 4], Vec3, usize, bool) {
    let p = |k: usize| &x[pair.ids[k] as usize];
    match pair.sides {
        Sides::PointTriangle(owns) => {
            let w = point_triangle(p(0), p(1), p(2), p(3));
            let zeros = w.iter().filter(|&&w| w == 0.0).count();
            let counts = match zeros {
                // An edge: the one opposite the zero weight (bits 0..3: ab, bc, ca).
                1 => {
                    let edge = match w.iter().position(|&w| w == 0.0) {
                        Some(2) => 0,
                        Some(0) => 1,
                        _ => 2,
                    };
                    owns >> edge & 1 == 1
                }
                // A corner (bits 3..6).
                2 => owns >> (3 + w.iter().position(|&w| w != 0.0).unwrap_or(0)) & 1 == 1,
                _ => true,
            };
            ([1.0, -w[0], -w[1], -w[2]], Vec3::zeros(), 4, counts)
        }
        Sides::EdgeEdge => {
            let (s, t) = segment_segment(p(0), p(1), p(2), p(3));
            let inside = s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0;
            ([1.0 - s, s, t - 1.0, -t], Vec3::zeros(), 4, inside)
        }
        Sides::Feature(anchor, _) => {
            let w = point_triangle(&anchor, p(0), p(1), p(2));
            ([w[0], w[1], w[2], 0.0], anchor, 3, true)
        }
    }
}

/// The length of a pair's gap at `x`.
pub(in crate::integrator) fn stencil_distance(pair: &Pair, x: &[Vec3]) -> f64 {
    let (w, anchor, len, _) = stencil(pair, x);
    let mut g = -anchor;
    for k in 0..len {
        g += x[pair.ids[k] as usize] * w[k];
    }
    g.norm()
}
