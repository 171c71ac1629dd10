//! The surface triangles of generated bodies: what contacts act on, what is drawn and what
//! is exported.

use crate::scene::Topology;

/// The triangles of a `rows × cols` sheet whose particle at `(r, c)` is `index(r, c)`: two per
/// grid square, split along the `(r, c)–(r+1, c+1)` diagonal, counter-clockwise seen from the
/// side the sheet's `(r+1) × (c+1)` cross product points to.
pub fn sheet(rows: usize, cols: usize, index: impl Fn(usize, usize) -> usize) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(2 * rows.saturating_sub(1) * cols.saturating_sub(1));
    let at = |r, c| index(r, c) as u32;
    for r in 0..rows.saturating_sub(1) {
        for c in 0..cols.saturating_sub(1) {
            out.push([at(r, c), at(r + 1, c), at(r + 1, c + 1)]);
            out.push([at(r, c), at(r + 1, c + 1), at(r, c + 1)]);
        }
    }
    out
}

/// The surface of a body whose particles start at `start`: a grid's sheet, a lattice's six
/// faces (outward), nothing for chains and points.
///
/// ```
/// use hooke_scene::{Topology, surface};
/// // A 3 × 3 cloth: 4 squares, 8 triangles.
/// assert_eq!(surface::triangles(Topology::Grid([3, 3]), 0).len(), 8);
/// // A 2 × 2 × 2 cube: 6 faces of 2 triangles.
/// assert_eq!(surface::triangles(Topology::Lattice([2, 2, 2]), 0).len(), 12);
/// ```
pub fn triangles(topology: Topology, start: usize) -> Vec<[u32; 3]> {
    match topology {
        Topology::Grid([a, b]) => sheet(a, b, |r, c| start + r * b + c),
        Topology::Lattice([a, b, c]) => {
            let idx = |i: usize, j: usize, k: usize| start + (i * b + j) * c + k;
            let flip =
                |t: Vec<[u32; 3]>| t.into_iter().map(|[p, q, r]| [p, r, q]).collect::<Vec<_>>();
            // Each face so that its triangles wind counter-clockwise seen from outside.
            let mut out = Vec::new();
            out.extend(sheet(a, b, |i, j| idx(i, j, 0)));
            out.extend(flip(sheet(a, b, |i, j| idx(i, j, c - 1))));
            out.extend(flip(sheet(a, c, |i, k| idx(i, 0, k))));
            out.extend(sheet(a, c, |i, k| idx(i, b - 1, k)));
            out.extend(sheet(b, c, |j, k| idx(0, j, k)));
            out.extend(flip(sheet(b, c, |j, k| idx(a - 1, j, k))));
            out
        }
        // Their triangles are the mesh's, not the topology's.
        Topology::Chain | Topology::Points | Topology::Mesh | Topology::Solid => Vec::new(),
    }
}
