//! Bending on triangles: Bergou et al. 2006's quadratic model, written exactly as
//! zero-rest-length springs (docs/physics.md §1.1, "Meshes"), on meshes without slivers.
//!
//! Across an interior edge `x0 x1` with opposite corners `x2` and `x3`, let `K` weigh the
//! four corners so that `Σ K_i x_i` is `|e|` times the sum of the two triangles' in-plane unit
//! normals to the edge at rest: `K_2 = |e| / h_2`, `K_3 = |e| / h_3` (the heights over the
//! edge) and `x0`, `x1` share `−K_2` and `−K_3` as the feet of the heights divide the edge.
//! Then `Σ K_i = 0`, `Σ K_i x_i = 0` for the flat hinge, and `|Σ K_i x_i| ≈ |e| θ` when it
//! folds by `θ`. The energy `(B / 6) · 3 / (A₁ + A₂) · |Σ K_i x_i|²` is the discrete
//! shells' `(B / 6) · 3|e|² θ² / (A₁ + A₂)`: on a sheet rolled to curvature `κ` only the
//! edges across the roll fold, and on regular meshes (right or equilateral triangles) the
//! weight `3|e|²/(A₁ + A₂)` sums to `3 κ²` per area, so `B / 6` gives `½ B κ²`. Since
//! `Σ K_i = 0`, `|Σ K_i x_i|² = −Σ_{i<j} K_i K_j |x_i − x_j|²`: six springs of rest length
//! zero and stiffness `−w K_i K_j`, with `w = B / (A₁ + A₂)`.

use crate::body::mesh::bending::PairSprings;
use crate::body::mesh::sheet::canonical;
use hooke_core::Vec3;
use std::collections::{BTreeMap, HashMap};

/// A triangle of a face, as bending sees it: its corners, its face, which way of cutting
/// the face it is from, and that way's weight. A quad is cut both ways, each at half
/// weight, so that its hinges are the same seen from either diagonal (one cut alone
/// couples bending to twist along the diagonals it picks); other faces are cut one way.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Piece {
    /// The triangle.
    pub(crate) corners: [u32; 3],
    /// Its face.
    pub(crate) face: u32,
    /// Which cut of the face.
    pub(crate) cut: u8,
    /// The cut's weight.
    pub(crate) weight: f64,
}

/// The pieces of `polygons` (particle indices).
pub(crate) fn pieces(polygons: &[Vec<u32>]) -> Vec<Piece> {
    let mut out = Vec::new();
    for (f, p) in polygons.iter().enumerate() {
        let face = f as u32;
        // Read from the lowest-numbered corner, so that the pieces do not depend on where
        // the file starts the face or which way it winds.
        let p = canonical(p);
        if p.len() == 4 {
            for (cut, tris) in [
                [[p[0], p[1], p[2]], [p[0], p[2], p[3]]],
                [[p[0], p[1], p[3]], [p[1], p[2], p[3]]],
            ]
            .into_iter()
            .enumerate()
            {
                for corners in tris {
                    out.push(Piece {
                        corners,
                        face,
                        cut: cut as u8,
                        weight: 0.5,
                    });
                }
            }
        } else {
            for k in 1..p.len() - 1 {
                out.push(Piece {
                    corners: [p[0], p[k], p[k + 1]],
                    face,
                    cut: 0,
                    weight: 1.0,
                });
            }
        }
    }
    out
}

/// The zero-rest-length springs of the bending energy of `triangles` (corner indices into
/// `x`, the rest shape) for a rigidity `bending` (N·m), summed per pair of particles, in
/// ascending order of the pair, and the largest `|e|/h` of any hinge. A hinge whose edge and one side are `pinned` and whose
/// other side is free is a clamped edge: of the material it stands for, only the free
/// triangle's side bends, so its weight is doubled (as a grid's clamped line element is,
/// which makes a cantilever's error second order in the spacing).
pub(crate) fn hinge_springs(
    x: &[Vec3],
    triangles: &[Piece],
    bending: f64,
    pinned: &dyn Fn(u32) -> bool,
) -> (PairSprings, f64) {
    let mut steepest = 0.0f64;
    let mut sides: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (t, piece) in triangles.iter().enumerate() {
        let tri = piece.corners;
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            sides.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    // Every pair of pieces on an edge from different faces, or from one face's one way of
    // cutting it, is a hinge.
    let mut hinges: Vec<((u32, u32), [usize; 2], f64)> = Vec::new();
    for (e, ts) in sides {
        for (m, &s) in ts.iter().enumerate() {
            for &t in &ts[m + 1..] {
                let (p, q) = (&triangles[s], &triangles[t]);
                let weight = if p.face != q.face {
                    p.weight * q.weight
                } else if p.cut == q.cut {
                    p.weight
                } else {
                    continue;
                };
                hinges.push((e, [s, t], weight));
            }
        }
    }
    hinges.sort_unstable_by_key(|h| (h.0, h.1));
    let mut out: BTreeMap<(u32, u32), f64> = BTreeMap::new();
    for ((a, b), [s, t], weight) in hinges {
        let opposite = |t: usize| {
            *triangles[t]
                .corners
                .iter()
                .find(|&&v| v != a && v != b)
                .expect("a triangle's third corner")
        };
        let (c, d) = (opposite(s), opposite(t));
        let corners = [a, b, c, d];
        let p = corners.map(|i| x[i as usize]);
        let e = p[1] - p[0];
        let len2 = e.norm_squared();
        let area = |q: Vec3| 0.5 * e.cross(&(q - p[0])).norm();
        let (a1, a2) = (area(p[2]), area(p[3]));
        if len2 == 0.0 || a1 == 0.0 || a2 == 0.0 {
            continue;
        }
        let mut k = [0.0; 4];
        for (m, q) in [(2, p[2]), (3, p[3])] {
            let along = (q - p[0]).dot(&e) / len2;
            let height = 2.0 * area(q) / len2.sqrt();
            let km = len2.sqrt() / height;
            steepest = steepest.max(km);
            k[m] += km;
            k[0] -= km * (1.0 - along);
            k[1] -= km * along;
        }
        let clamped = pinned(a) && pinned(b) && (pinned(c) != pinned(d));
        let w = weight * bending / (a1 + a2) * if clamped { 2.0 } else { 1.0 };
        for i in 0..4 {
            for j in i + 1..4 {
                let (u, v) = (corners[i], corners[j]);
                *out.entry((u.min(v), u.max(v))).or_insert(0.0) -= w * k[i] * k[j];
            }
        }
    }
    let springs = out.into_iter().filter(|(_, k)| *k != 0.0).collect();
    (springs, steepest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::mesh::bending::rolls::rolled_errors;

    /// A sheet rolled onto a cylinder of curvature κ either way stores `½ B κ²` per area:
    /// within 5 % on a regular mesh (its boundary's hinges are missing), within 10 % on an
    /// irregular one; nothing when flat.
    #[test]
    fn a_rolled_sheet_stores_half_b_kappa_squared_per_area() {
        for (jitter, tolerance) in [(0.0, 0.05), (0.3, 0.1)] {
            let errors = rolled_errors(jitter, &|x, polygons, b| {
                let pieces: Vec<Piece> = polygons
                    .iter()
                    .enumerate()
                    .map(|(f, t)| Piece {
                        corners: [t[0], t[1], t[2]],
                        face: f as u32,
                        cut: 0,
                        weight: 1.0,
                    })
                    .collect();
                hinge_springs(x, &pieces, b, &|_| false).0
            });
            assert!(
                errors.iter().all(|e| e.abs() < tolerance),
                "{jitter}: {errors:?}"
            );
        }
    }
}
