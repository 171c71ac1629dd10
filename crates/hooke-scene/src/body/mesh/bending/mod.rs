//! Bending on a mesh: Bergou's hinges where every triangle is well shaped, second
//! derivatives fitted to the vertices' neighbourhoods where some are slivers
//! (docs/physics.md §1.1, "Meshes").
//!
//! Both store `½ B κ²` per area on a roll. The hinges weigh an edge by `|e|/h` over its
//! triangles' heights, so on a sliver they are stiffer than any curvature the mesh can hold
//! by `(|e|/h)²`, and set the step. The fit is exact on quadratics and bounded on slivers,
//! but block descent at the drape meter's tolerance leaves a cloth with fitted bending
//! stiffer than small steps do (benches/README.md, "Bending fitted to the points"). So a mesh
//! keeps its hinges unless one is steeper than [`SLIVER`].

pub(crate) mod fitted;
pub(crate) mod hinges;
#[cfg(test)]
mod rolls;

/// Zero-rest-length springs summed per pair of particles: `((i, j), ks)`, `i < j`, in
/// ascending order of the pair.
pub(crate) type PairSprings = Vec<((u32, u32), f64)>;

/// The steepest hinge, `|e|/h`, a mesh may have and keep its hinges: a right triangle's
/// diagonal has 2, the meter's polar disc 3.5, the round tablecloth 3.9.
pub(crate) const SLIVER: f64 = 10.0;

/// The zero-rest springs of a mesh's bending (see [`hinges::hinge_springs`] for `pinned`),
/// and, when its slivers made them fitted ones, its steepest hinge.
pub(crate) fn springs(
    x: &[hooke_core::Vec3],
    polygons: &[Vec<u32>],
    bending: f64,
    pinned: &dyn Fn(u32) -> bool,
) -> (PairSprings, Option<f64>) {
    let (on_hinges, steepest) =
        hinges::hinge_springs(x, &hinges::pieces(polygons), bending, pinned);
    if steepest <= SLIVER {
        (on_hinges, None)
    } else {
        (fitted::fitted_springs(x, polygons, bending), Some(steepest))
    }
}
