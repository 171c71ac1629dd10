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
    triangles: Vec<[u32; 3]>,
    /// The surfaces' particles, for the step's largest move.
    particles: Vec<u32>,
    /// The thinnest contact thickness of the active surfaces (infinite without one).
    pub(crate) thickness: f64,
    /// The watch on what self-contact skips: its triangles' planes, kept between steps.
    pub(crate) planes: Vec<crate::contact::exclusion::Plane>,
}

impl CrossingWatch {
    fn build(&mut self, model: &Model) {
        self.built = true;
        self.thickness = f64::INFINITY;
        for (_, s) in model.active_surfaces() {
            self.edges.extend(s.edges());
            self.triangles.extend_from_slice(&s.triangles);
            self.particles.extend(s.particles.clone().map(|i| i as u32));
            self.thickness = self.thickness.min(s.thickness);
        }
    }

    /// Whether the model has anything to watch: a surface with a thickness and a collider
    /// with a velocity-level response.
    pub(crate) fn watches(&mut self, model: &Model) -> bool {
        if !self.built {
            self.build(model);
        }
        !self.edges.is_empty() && model.colliders.iter().any(|c| !c.response.is_force())
    }

    /// The largest distance a surface particle moved from `start` to `x`.
    pub(crate) fn largest_move(&self, start: &[Vec3], x: &[Vec3]) -> f64 {
        self.particles
            .par_chunks(CHUNK)
            .map(|ids| {
                ids.iter()
                    .map(|&i| (x[i as usize] - start[i as usize]).norm())
                    .fold(0.0, f64::max)
            })
            .reduce(|| 0.0, f64::max)
    }

    /// The first collider (in model order) that a surface passes through at `x`, and the
    /// particles of the first edge or triangle that does (in surface order; an edge's first
    /// end twice): the same on any thread count.
    pub(crate) fn first_crossing(&self, model: &Model, x: &[Vec3]) -> Option<(usize, [u32; 3])> {
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
                return Some((k, [a, b, a]));
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
                    let (lo, hi) = (a.inf(b).inf(c), a.sup(b).sup(c));
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
                return Some((k, tri));
            }
        }
        None
    }
}
