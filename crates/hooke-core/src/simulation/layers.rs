//! The watch on layers (docs/physics.md §3.5, "Layers after a large step"): after a step
//! of an integrator whose contacts come after it, whether a surface ended it through itself
//! or through another surface.
//!
//! The contact phase keeps two measured layers apart while neither closes on the other by
//! more than the thickness between two looks: at a step that moved no surface particle
//! more than half the thinnest thickness relative to the surfaces' mean move (two
//! particles then close by at most the thickness, whatever they share). Only the other
//! steps are looked at, a large explicit or implicit step's, on every triangle pair of
//! surfaces that touch, sharing no particle, found by a uniform grid of their boxes.
//! Pairs that only a skipped pair could bring through each other are the folds watch's
//! (`contact::exclusion::Folds`), which says them as a crease.

use crate::contact::exclusion::{Folds, Plane, through};
use crate::contact::grid::Grid;
use crate::particles::Vec3;
use rayon::prelude::*;

/// Triangles per parallel chunk.
const CHUNK: usize = 256;

/// The buffers of a look; the surfaces' triangles are the crossing watch's
/// (`simulation::watch::CrossingWatch`).
#[derive(Clone, Debug, Default)]
pub(crate) struct LayerWatch {
    planes: Vec<Plane>,
    boxes: Vec<(Vec3, Vec3)>,
    grid: Grid,
}

/// A triangle pair through each other: the surfaces (their indices among the model's
/// surfaces) of the triangle whose edge passes and of the other, and their corners, the
/// passing edge's ends first.
pub(crate) struct Crossing {
    pub(crate) surfaces: [usize; 2],
    pub(crate) corners: [[u32; 3]; 2],
}

impl LayerWatch {
    /// For each pair of surfaces that touch (a surface and itself included), the first
    /// triangle pair of them (by the lower triangle in the surfaces' order, so the same on
    /// any thread count) of which an edge of one passes through the other at `x`; pairs
    /// sharing a particle, and those `folds` watches, are left out.
    pub(crate) fn crossings(
        &mut self,
        (triangles, surface): (&[[u32; 3]], &[u32]),
        self_colliding: &(dyn Fn(u32) -> bool + Sync),
        x: &[Vec3],
        folds: &Folds,
    ) -> Vec<Crossing> {
        triangles
            .par_iter()
            .with_min_len(CHUNK)
            .map(|t| Plane::of(t, x))
            .collect_into_vec(&mut self.planes);
        triangles
            .par_iter()
            .with_min_len(CHUNK)
            .map(|t| {
                let [a, b, c] = t.map(|i| x[i as usize]);
                (a.inf(&b).inf(&c), a.sup(&b).sup(&c))
            })
            .collect_into_vec(&mut self.boxes);
        // Cells as large as the largest box, so a box's partners lie in the 27 cells
        // around its low corner's.
        let cell = self
            .boxes
            .iter()
            .map(|(lo, hi)| (hi - lo).max())
            .fold(0.0, f64::max);
        if !(cell.is_finite() && cell > 0.0) {
            // Positions beyond numbers are the divergence check's to say.
            return Vec::new();
        }
        self.grid.build(cell, self.boxes.iter().map(|b| b.0));
        let (planes, boxes, grid) = (&self.planes, &self.boxes, &self.grid);
        let touch = |i: usize, j: usize| surface[i] != surface[j] || self_colliding(surface[i]);
        // Every pair is looked at (a look that finds nothing, the usual one, does so
        // anyway), so that each pair of surfaces is said at every step it crossed.
        let found: Vec<(usize, usize, [u32; 3])> = (0..triangles.len())
            .into_par_iter()
            .with_min_len(CHUNK)
            .flat_map_iter(|i| {
                let ta = &triangles[i];
                let [cx, cy, cz] = grid.cell_of(&boxes[i].0);
                let mut found = Vec::new();
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            grid.visit([cx + dx, cy + dy, cz + dz], |j| {
                                let j = j as usize;
                                if j <= i || !overlap(&boxes[i], &boxes[j]) {
                                    return;
                                }
                                let tb = &triangles[j];
                                if ta.iter().any(|v| tb.contains(v))
                                    || !touch(i, j)
                                    || folds.watches(i as u32, j as u32)
                                {
                                    return;
                                }
                                // Only a triangle's first crossing with each surface can
                                // be its pair's first: a tangle of thousands keeps one.
                                let seen = |&(_, k, _): &(usize, usize, [u32; 3])| {
                                    surface[k] == surface[j]
                                };
                                if found.iter().any(seen) {
                                    return;
                                }
                                if let Some(corners) =
                                    through((ta, &planes[i]), (tb, &planes[j]), x)
                                {
                                    found.push((i, j, corners));
                                }
                            });
                        }
                    }
                }
                found
            })
            .collect();
        // The first crossing of each pair of surfaces, in the order found: by the lower
        // triangle, then the grid's order, the same on any thread count.
        let mut first: Vec<Crossing> = Vec::new();
        for (i, j, corners) in found {
            let (si, sj) = (surface[i] as usize, surface[j] as usize);
            if first
                .iter()
                .any(|c| c.surfaces == [si, sj] || c.surfaces == [sj, si])
            {
                continue;
            }
            first.push(if triangles[i].contains(&corners[0]) {
                Crossing {
                    surfaces: [si, sj],
                    corners: [corners, triangles[j]],
                }
            } else {
                Crossing {
                    surfaces: [sj, si],
                    corners: [corners, triangles[i]],
                }
            });
        }
        first
    }
}

/// Whether two boxes overlap.
fn overlap((a0, a1): &(Vec3, Vec3), (b0, b1): &(Vec3, Vec3)) -> bool {
    (0..3).all(|k| a0[k] <= b1[k] && b0[k] <= a1[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crossings a look finds among `triangles`, each on the surface beside it, with
    /// `self_collision` per surface.
    fn look(triangles: &[([u32; 3], u32)], self_collision: &[bool], x: &[Vec3]) -> Vec<Crossing> {
        let (tris, surface): (Vec<_>, Vec<_>) = triangles.iter().copied().unzip();
        LayerWatch::default().crossings(
            (&tris, &surface),
            &|k| self_collision[k as usize],
            x,
            &Folds::default(),
        )
    }

    /// A flat triangle in y = 0 (particles 0–2), an upright one whose edge 3–4 passes
    /// through it (particles 3–5), and a flat one beside the first (6, 7 and 2).
    fn positions() -> Vec<Vec3> {
        vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.1, 1.0, 0.1),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
        ]
    }

    #[test]
    fn an_edge_through_another_surface_is_found_with_both_surfaces() {
        let found = look(
            &[([0, 1, 2], 0), ([3, 4, 5], 1)],
            &[false, false],
            &positions(),
        );
        assert_eq!(found.len(), 1);
        assert_eq!(
            found[0].surfaces,
            [1, 0],
            "the upright triangle's edge passes"
        );
        assert_eq!(found[0].corners, [[3, 4, 5], [0, 1, 2]]);
    }

    #[test]
    fn each_pair_of_surfaces_crossed_is_found_once() {
        // The upright triangle (surface 1) passes through the flat one (surface 0); a
        // copy of it beside (surface 2, particles 5–7 moved onto it) passes through it
        // too, and a second flat triangle of surface 0 under both adds no pair.
        let mut x = positions();
        x[6] = x[3] + Vec3::new(0.01, 0.0, 0.0);
        x[7] = x[4] + Vec3::new(0.01, 0.0, 0.0);
        x.push(x[5] + Vec3::new(0.01, 0.0, 0.0));
        x.extend([
            Vec3::new(-1.0, 0.0, -1.1),
            Vec3::new(1.0, 0.0, -1.1),
            Vec3::new(0.0, 0.0, 0.9),
        ]);
        let tris = [
            ([0, 1, 2], 0),
            ([3, 4, 5], 1),
            ([6, 7, 8], 2),
            ([9, 10, 11], 0),
        ];
        let found = look(&tris, &[false, false, false], &x);
        let pairs: Vec<_> = found.iter().map(|c| c.surfaces).collect();
        assert_eq!(pairs, [[1, 0], [2, 0]]);
    }

    #[test]
    fn one_surface_through_itself_counts_only_where_it_collides_with_itself() {
        let tris = [([0, 1, 2], 0), ([3, 4, 5], 0)];
        let x = positions();
        assert!(look(&tris, &[false], &x).is_empty());
        let found = look(&tris, &[true], &x);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].surfaces, [0, 0]);
    }

    #[test]
    fn neighbours_in_one_plane_and_triangles_apart_are_not_through() {
        let mut x = positions();
        let tris = [([0, 1, 2], 0), ([6, 7, 2], 0), ([3, 4, 5], 0)];
        // Lift the upright triangle clear of the flat ones.
        for p in &mut x[3..6] {
            p.y += 2.5;
        }
        assert!(look(&tris, &[true], &x).is_empty());
    }
}
