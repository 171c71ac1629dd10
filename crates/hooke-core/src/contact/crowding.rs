//! How many candidate pairs the contact phase may hold (docs/physics.md §3.3): more than
//! surfaces kept a thickness apart can bring within the reach of each other means that a
//! step has crushed or torn them through themselves, and the run stops as diverged
//! instead of gathering pairs until memory runs out.
//!
//! A step far beyond an explicit integrator's stable step can blow a flat cloth up in its
//! own plane: its triangles grow metres long and lie over one another, every particle in
//! the plane of thousands of them. The 128² tablecloth under symplectic Euler at 1/60 s
//! found 40 million point–triangle pairs at its fourth step and went on to ask for 24 GB.
//! The energy watch would say so after the step; the gather comes first.

use crate::particles::Vec3;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The factor on the bound below: room for meshes finer in places than on average.
const SLACK: f64 = 4.0;
/// So many pairs per primitive are always allowed, however coarse the mesh.
const FLOOR_PER_PRIMITIVE: f64 = 64.0;
/// So many pairs are always allowed (a small scene never meets its cap).
const FLOOR: usize = 1 << 20;

/// Caps on the point–triangle and edge–edge candidate lists.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Caps {
    pub(super) point_tri: usize,
    pub(super) edge_edge: usize,
}

impl Caps {
    /// The caps for surfaces with `points` particles, `tris` triangles and `edges` edges at
    /// rest positions `rest`, thinnest thickness `h` and candidate reach `reach`.
    ///
    /// Around a particle, layers kept at least `h` apart stack at most `1 + 2 reach / h`
    /// deep within the reach. Each brings within it the triangles of a disc of radius
    /// `reach` plus an edge, `π (reach + ē)² / ā` of them at the mean rest edge `ē` and
    /// triangle area `ā`. An edge meets, in each layer, the edges whose midpoints lie
    /// within the reach plus an edge of it: a capsule of area `π (reach + ē)² + 2 (reach +
    /// ē) ē`, with a mesh's one and a half edges per triangle.
    pub(super) fn new(
        rest: &[Vec3],
        (points, tris, edges): (usize, &[[u32; 3]], &[[u32; 2]]),
        h: f64,
        reach: f64,
    ) -> Self {
        let n_tris = tris.len().max(1) as f64;
        let n_edges = edges.len().max(1) as f64;
        let area = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| rest[i as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum::<f64>()
            / n_tris;
        let edge = edges
            .iter()
            .map(|[a, b]| (rest[*a as usize] - rest[*b as usize]).norm())
            .sum::<f64>()
            / n_edges;
        let layers = 1.0 + 2.0 * reach / h;
        let r = reach + edge;
        let disc = std::f64::consts::PI * r * r;
        let per_point = SLACK * layers * disc / area;
        let per_edge = SLACK * layers * 1.5 * (disc + 2.0 * r * edge) / area;
        let cap = |per: f64, n: usize| {
            let per = if per.is_finite() { per } else { 0.0 };
            let total = per.max(FLOOR_PER_PRIMITIVE) * n as f64;
            (total.min(usize::MAX as f64) as usize).max(FLOOR)
        };
        Self {
            point_tri: cap(per_point, points),
            edge_edge: cap(per_edge, edges.len()),
        }
    }
}

/// A count of pairs kept, shared by a gather's parallel chunks. Whether it passes its
/// limit depends only on the positions: a chunk stops once the count is past the limit,
/// which it can only be when all the chunks together find more.
pub(super) struct Count {
    limit: usize,
    count: AtomicUsize,
}

impl Count {
    /// A count from zero up to `limit`.
    pub(super) fn new(limit: usize) -> Self {
        Self {
            limit,
            count: AtomicUsize::new(0),
        }
    }

    /// Whether the pairs counted are past the limit: a chunk finds no more.
    pub(super) fn full(&self) -> bool {
        self.count.load(Ordering::Relaxed) > self.limit
    }

    /// Counts `n` more pairs.
    pub(super) fn add(&self, n: usize) {
        if n > 0 {
            self.count.fetch_add(n, Ordering::Relaxed);
        }
    }

    /// `Err` with the limit when the pairs found are more than it allows.
    pub(super) fn verdict(&self) -> Result<(), Crowded> {
        if self.full() {
            Err(Crowded { limit: self.limit })
        } else {
            Ok(())
        }
    }
}

/// The contact phase found more candidate pairs than its surfaces can hold apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Crowded {
    /// The pairs allowed, which were passed.
    pub(crate) limit: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cap sits between what a pile of layers a thickness apart holds and what a
    /// cloth blown up in its own plane finds: every particle of a 64² sheet within the
    /// reach of every other's triangles.
    #[test]
    fn a_stack_of_layers_fits_and_a_sheet_over_itself_does_not() {
        let (spacing, h) = (0.01, 0.0025);
        let reach = 3.0 * h;
        let at = |i: usize, j: usize| Vec3::new(i as f64 * spacing, 0.0, j as f64 * spacing);
        let (model, x) = crate::contact::exclusion::tests::sheet(64, h, |_, _| false, at);
        let (tris, edges) = (&model.surfaces[0].triangles, model.surfaces[0].edges());
        let caps = Caps::new(&x, (x.len(), tris, &edges), h, reach);
        // Seven layers a thickness apart (the most the reach can hold around a particle):
        // each particle within the reach of about (2 reach / spacing)² · 2 triangles of each.
        let stacked = x.len() as f64 * 7.0 * 2.0 * (2.0 * reach / spacing + 1.0).powi(2);
        assert!(
            (caps.point_tri as f64) > 2.0 * stacked,
            "{} against {stacked}",
            caps.point_tri
        );
        let everything = x.len() * tris.len();
        assert!(caps.point_tri < everything / 4, "{}", caps.point_tri);
        assert!(caps.edge_edge < edges.len() * edges.len() / 8);
    }

    /// The count's verdict: past the limit only when more were added than it allows.
    #[test]
    fn the_count_is_full_only_past_its_limit() {
        let count = Count::new(10);
        count.add(10);
        assert!(!count.full() && count.verdict().is_ok());
        count.add(1);
        assert!(count.full());
        assert_eq!(count.verdict(), Err(Crowded { limit: 10 }));
    }
}
