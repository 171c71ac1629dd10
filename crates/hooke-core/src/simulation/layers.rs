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
use crate::model::Model;
use crate::particles::Vec3;
use rayon::prelude::*;

/// Triangles per parallel chunk.
const CHUNK: usize = 256;

/// The surfaces that touch, their triangles indexed as the contact phase's exclusion
/// indexes them, built once per model, and the buffers of a look.
#[derive(Clone, Debug, Default)]
pub(crate) struct LayerWatch {
    built: bool,
    triangles: Vec<[u32; 3]>,
    /// Each triangle's surface (its index among the model's surfaces).
    surface: Vec<u32>,
    /// Per surface of the model: whether it collides with itself.
    self_collision: Vec<bool>,
    /// The surfaces' particles, for the step's move.
    particles: Vec<u32>,
    /// The thinnest thickness of the surfaces that touch (infinite without any).
    pub(crate) thickness: f64,
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
    fn build(&mut self, model: &Model) {
        self.built = true;
        self.thickness = f64::INFINITY;
        if !model.surfaces_touch() {
            return;
        }
        self.self_collision = model.surfaces.iter().map(|s| s.self_collision).collect();
        // In the contact phase's order (`contact::Contacts::prepare`), so that a triangle's
        // index is the exclusion's.
        for (k, s) in model.active_surfaces() {
            self.triangles.extend_from_slice(&s.triangles);
            self.surface
                .extend(std::iter::repeat_n(k as u32, s.triangles.len()));
            self.particles.extend(s.particles.clone().map(|i| i as u32));
            self.thickness = self.thickness.min(s.thickness);
        }
    }

    /// Whether the model has surfaces that can touch, with triangles to pass through.
    pub(crate) fn watches(&mut self, model: &Model) -> bool {
        if !self.built {
            self.build(model);
        }
        !self.triangles.is_empty()
    }

    /// The largest move of a surface particle from `start` to `x` relative to the
    /// surfaces' mean move, metres. The mean is summed in particle order, so the same on
    /// any thread count.
    pub(crate) fn relative_move(&self, start: &[Vec3], x: &[Vec3]) -> f64 {
        let d = |i: u32| x[i as usize] - start[i as usize];
        let mean = self.particles.iter().fold(Vec3::zeros(), |m, &i| m + d(i))
            / self.particles.len() as f64;
        self.particles
            .par_iter()
            .with_min_len(4 * CHUNK)
            .map(|&i| (d(i) - mean).norm())
            .reduce(|| 0.0, f64::max)
    }

    /// The first triangle (in the surfaces' order, so the same on any thread count) of
    /// which an edge passes through a triangle of a surface it touches, or that a
    /// triangle's edge passes through, at `x`; pairs sharing a particle, and those `folds`
    /// watches, are left out.
    pub(crate) fn first_through(&mut self, x: &[Vec3], folds: &Folds) -> Option<Crossing> {
        let triangles = &self.triangles;
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
            return None;
        }
        self.grid.build(cell, self.boxes.iter().map(|b| b.0));
        let (planes, boxes, grid) = (&self.planes, &self.boxes, &self.grid);
        let (surface, self_collision) = (&self.surface, &self.self_collision);
        let touch =
            |i: usize, j: usize| surface[i] != surface[j] || self_collision[surface[i] as usize];
        (0..triangles.len())
            .into_par_iter()
            .with_min_len(CHUNK)
            .find_map_first(|i| {
                let ta = &triangles[i];
                let [cx, cy, cz] = grid.cell_of(&boxes[i].0);
                let mut found = None;
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            grid.visit([cx + dx, cy + dy, cz + dz], |j| {
                                let j = j as usize;
                                if found.is_some() || j <= i || !overlap(&boxes[i], &boxes[j]) {
                                    return;
                                }
                                let tb = &triangles[j];
                                if ta.iter().any(|v| tb.contains(v))
                                    || !touch(i, j)
                                    || folds.watches(i as u32, j as u32)
                                {
                                    return;
                                }
                                found = through((ta, &planes[i]), (tb, &planes[j]), x)
                                    .map(|corners| (j, corners));
                            });
                        }
                    }
                }
                let (j, corners) = found?;
                let (si, sj) = (surface[i] as usize, surface[j] as usize);
                Some(if ta.contains(&corners[0]) {
                    Crossing {
                        surfaces: [si, sj],
                        corners: [corners, triangles[j]],
                    }
                } else {
                    Crossing {
                        surfaces: [sj, si],
                        corners: [corners, *ta],
                    }
                })
            })
    }
}

/// Whether two boxes overlap.
fn overlap((a0, a1): &(Vec3, Vec3), (b0, b1): &(Vec3, Vec3)) -> bool {
    (0..3).all(|k| a0[k] <= b1[k] && b0[k] <= a1[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A watch over `triangles`, each on the surface beside it, with `self_collision` per
    /// surface.
    fn watch(triangles: &[([u32; 3], u32)], self_collision: &[bool]) -> LayerWatch {
        LayerWatch {
            built: true,
            triangles: triangles.iter().map(|t| t.0).collect(),
            surface: triangles.iter().map(|t| t.1).collect(),
            self_collision: self_collision.to_vec(),
            particles: (0..8).collect(),
            thickness: 0.005,
            ..LayerWatch::default()
        }
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
        let mut w = watch(&[([0, 1, 2], 0), ([3, 4, 5], 1)], &[false, false]);
        let found = w.first_through(&positions(), &Folds::default()).unwrap();
        assert_eq!(found.surfaces, [1, 0], "the upright triangle's edge passes");
        assert_eq!(found.corners, [[3, 4, 5], [0, 1, 2]]);
    }

    #[test]
    fn one_surface_through_itself_counts_only_where_it_collides_with_itself() {
        let tris = [([0, 1, 2], 0), ([3, 4, 5], 0)];
        let x = positions();
        assert!(
            watch(&tris, &[false])
                .first_through(&x, &Folds::default())
                .is_none()
        );
        let found = watch(&tris, &[true])
            .first_through(&x, &Folds::default())
            .unwrap();
        assert_eq!(found.surfaces, [0, 0]);
    }

    #[test]
    fn neighbours_in_one_plane_and_triangles_apart_are_not_through() {
        let mut x = positions();
        let tris = [([0, 1, 2], 0), ([6, 7, 2], 0), ([3, 4, 5], 0)];
        // Lift the upright triangle clear of the flat ones.
        for p in &mut x[3..6] {
            p.y += 2.5;
        }
        assert!(
            watch(&tris, &[true])
                .first_through(&x, &Folds::default())
                .is_none()
        );
    }

    #[test]
    fn a_shared_motion_is_no_relative_move() {
        let w = watch(&[([0, 1, 2], 0)], &[true]);
        let start = positions();
        let shift = Vec3::new(0.3, -2.0, 0.1);
        let mut x: Vec<Vec3> = start.iter().map(|p| p + shift).collect();
        assert!(w.relative_move(&start, &x) < 1e-12);
        x[7].y += 0.01;
        let moved = w.relative_move(&start, &x);
        assert!((moved - 0.01 * 7.0 / 8.0).abs() < 1e-12, "{moved}");
    }
}
