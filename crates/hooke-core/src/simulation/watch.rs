//! The crossing watch (docs/physics.md §3.5): after a step that could have let a surface
//! through a collider, whether one did. A surface passes through a collider when one of its
//! edges meets the collider's solid ([`crate::Collider::segment_meets`]: an end inside, or
//! the inside between the ends) or a sharp feature of the collider (an edge, a rim) passes
//! through one of its triangles. Only colliders with a velocity-level response count:
//! a penalty collider is entered by design.
//!
//! Which steps could: every step of an integrator whose contacts come after it when the
//! step moved a surface particle farther than half the thinnest contact thickness (the
//! contact phase keeps surfaces out while it sees every proximity before it becomes a
//! crossing), or when a collider moved that far; and every block-descent step with a moving
//! collider (whose parts can run out, or meet a pinned particle). Other steps cost nothing.

use crate::contact::proximity::feature_triangle;
use crate::model::Model;
use crate::particles::Vec3;
use rayon::prelude::*;

/// A feature nearer a triangle than this passes through it, metres (a circle's nearest
/// point is found by search, to about 1e-8 of its radius).
const THROUGH: f64 = 1e-7;

/// Edges or triangles per parallel chunk.
const CHUNK: usize = 512;

/// The surfaces' edges and triangles, built once per model.
#[derive(Clone, Debug, Default)]
pub(crate) struct CrossingWatch {
    built: bool,
    edges: Vec<[u32; 2]>,
    /// The active surfaces' triangles in model order (the contact phase's, so that a
    /// triangle's index is its exclusion's), and each one's surface.
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) surface: Vec<u32>,
    /// The surfaces' particles, for the step's largest move.
    particles: Vec<u32>,
    /// The thinnest contact thickness of the active surfaces (infinite without one).
    pub(crate) thickness: f64,
    /// The watch on what self-contact skips: its triangles' planes, kept between steps.
    pub(crate) planes: Vec<crate::contact::exclusion::Plane>,
}

impl CrossingWatch {
    /// Reads the model's active surfaces, once.
    pub(crate) fn build(&mut self, model: &Model) {
        if self.built {
            return;
        }
        self.built = true;
        self.thickness = f64::INFINITY;
        for (k, s) in model.active_surfaces() {
            self.edges.extend(s.edges());
            self.triangles.extend_from_slice(&s.triangles);
            self.surface
                .extend(std::iter::repeat_n(k as u32, s.triangles.len()));
            self.particles.extend(s.particles.clone().map(|i| i as u32));
            self.thickness = self.thickness.min(s.thickness);
        }
    }

    /// Whether the model has anything to watch: a surface with a thickness and a collider
    /// with a velocity-level response.
    pub(crate) fn watches(&mut self, model: &Model) -> bool {
        self.build(model);
        !self.edges.is_empty() && model.colliders.iter().any(|c| !c.response.is_force())
    }

    /// The largest distance a surface particle moved from `start` to `x`, less `shift`
    /// (zero for the distance itself).
    pub(crate) fn largest_move(&self, start: &[Vec3], x: &[Vec3], shift: Vec3) -> f64 {
        self.particles
            .par_chunks(CHUNK)
            .map(|ids| {
                ids.iter()
                    .map(|&i| (x[i as usize] - start[i as usize] - shift).norm())
                    .fold(0.0, f64::max)
            })
            .reduce(|| 0.0, f64::max)
    }

    /// The surface particles' mean move from `start` to `x`, summed in particle order so
    /// that it is the same on any thread count.
    pub(crate) fn mean_move(&self, start: &[Vec3], x: &[Vec3]) -> Vec3 {
        let sum = self.particles.iter().fold(Vec3::zeros(), |m, &i| {
            m + (x[i as usize] - start[i as usize])
        });
        sum / self.particles.len() as f64
    }

    /// Each collider (in model order) that a surface passes through at `x`, with the
    /// particles of the first edge or triangle that does (in surface order; an edge's first
    /// end twice): the same on any thread count.
    pub(crate) fn crossings(&self, model: &Model, x: &[Vec3]) -> Vec<(usize, [u32; 3])> {
        let mut found = Vec::new();
        for (k, slot) in model.colliders.iter().enumerate() {
            if slot.response.is_force() {
                continue;
            }
            let shape = &*slot.shape;
            let edge = self
                .edges
                .par_iter()
                .with_min_len(CHUNK)
                .find_first(|&&[a, b]| {
                    let (p, q) = (&x[a as usize], &x[b as usize]);
                    let (lo, hi) = (p.inf(q), p.sup(q));
                    shape.may_touch(&lo, &hi, 0.0) && shape.segment_meets(p, q)
                });
            if let Some(&[a, b]) = edge {
                found.push((k, [a, b, a]));
                continue;
            }
            if !shape.has_features() {
                continue;
            }
            let triangle = self
                .triangles
                .par_iter()
                .with_min_len(CHUNK)
                .find_first(|tri| {
                    let [a, b, c] = tri.map(|i| &x[i as usize]);
                    // Grown by what counts as through: a feature that near the triangle
                    // may lie just outside its box.
                    let (lo, hi) = (
                        a.inf(b).inf(c).add_scalar(-THROUGH),
                        a.sup(b).sup(c).add_scalar(THROUGH),
                    );
                    let mut through = false;
                    shape.features(&lo, &hi, &mut |f| {
                        if !through {
                            let (anchor, w) = feature_triangle(&f, a, b, c);
                            through = (a * w[0] + b * w[1] + c * w[2] - anchor).norm() < THROUGH;
                        }
                    });
                    through
                });
            if let Some(&tri) = triangle {
                found.push((k, tri));
            }
        }
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shared_motion_is_no_relative_move() {
        let w = CrossingWatch {
            particles: (0..8).collect(),
            ..CrossingWatch::default()
        };
        let start: Vec<Vec3> = (0..8).map(|i| Vec3::new(i as f64, 0.5, -0.2)).collect();
        let shift = Vec3::new(0.3, -2.0, 0.1);
        let mut x: Vec<Vec3> = start.iter().map(|p| p + shift).collect();
        let relative = |x: &[Vec3]| w.largest_move(&start, x, w.mean_move(&start, x));
        assert!(relative(&x) < 1e-12);
        x[7].y += 0.01;
        let moved = relative(&x);
        assert!((moved - 0.01 * 7.0 / 8.0).abs() < 1e-12, "{moved}");
    }
}
