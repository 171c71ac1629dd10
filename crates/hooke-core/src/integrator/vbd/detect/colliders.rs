//! The detection's colliders: per particle the nearest collider surface and the planes it
//! may touch, per surface triangle the nearest sharp feature and the feature pairs
//! (docs/physics.md §4.1).

use super::{CONTACT_STIFFNESS, Clearance, Detection, FELT};
use crate::collider::response::Response;
use crate::contact::proximity::feature_triangle;
use crate::integrator::vbd::cells::{bounds_of, each_chunk};
use crate::integrator::vbd::pairs::{Pair, Sides};
use crate::integrator::vbd::planes::{HalfSpaces, Lists, Plane, Touches};
use crate::model::Model;
use crate::particles::Vec3;

/// The normal stiffness and Coulomb coefficient a collider's response gives a contact with
/// stiffness scale `scale`.
pub(in crate::integrator) fn collider_law(response: &Response, scale: f64) -> (f64, f64) {
    match *response {
        Response::Penalty { kc, .. } => (kc, 0.0),
        Response::Restitution { friction, .. } => (CONTACT_STIFFNESS * scale, friction),
        Response::Stick => (CONTACT_STIFFNESS * scale, f64::INFINITY),
    }
}

/// What a chunk of particles' collider search found, per particle in order; kept between
/// detections so that a detection allocates nothing once its buffers have grown.
#[derive(Clone, Debug, Default)]
pub(super) struct Found {
    clearances: Vec<Clearance>,
    touches: Lists<Plane>,
    halves: Lists<(Vec3, Vec3, f64)>,
}

/// What a chunk of triangles' feature search found: each triangle's clearance, and the
/// chunk's pairs in triangle order; kept between detections as [`Found`] is.
#[derive(Clone, Debug, Default)]
pub(super) struct FeaturesFound {
    clearances: Vec<Clearance>,
    pairs: Vec<Pair>,
}

impl Detection {
    /// Per particle: the nearest collider surface (capped at `reach`) and which colliders
    /// it may touch before the next detection.
    pub(super) fn detect_colliders(&mut self, model: &Model, x: &[Vec3], reach: f64) {
        let topology = &self.topology;
        let one = |i: usize, found: &mut Found| {
            let (lo, hi) = (x[i].add_scalar(-reach), x[i].add_scalar(reach));
            let mut clearance = Clearance::new(reach);
            let mut near = Touches::default();
            let mut halves = HalfSpaces::default();
            for (k, slot) in model.colliders.iter().enumerate() {
                if !slot.shape.may_touch(&lo, &hi, 0.0) {
                    continue;
                }
                let half = slot.shape.is_half_space();
                // A penalty collider is a force field the course lets particles enter: it
                // bounds nothing, and its surface is felt wherever the search reaches.
                let force = slot.response.is_force();
                let margin = topology.keeps(model, i, &slot.response);
                slot.shape.contacts_within(&x[i], reach, &mut |c| {
                    let d = reach - c.depth;
                    // Inside already: no bound from it (staying is no crossing); its
                    // contact pushes the particle out.
                    let inside = d < 0.0;
                    let felt = force || inside || d <= FELT * margin;
                    // A half-space bounds only the motion along its normal.
                    let kept = half && !force && !inside && halves.keep(c.point, c.normal, d);
                    if !force && !inside && !kept {
                        clearance.see(d, felt);
                    }
                    if felt {
                        let plane = Plane {
                            collider: k as u16,
                            point: c.point,
                            normal: c.normal,
                        };
                        near.keep(plane, d);
                    }
                });
            }
            found.clearances.push(clearance);
            found.touches.push(near.planes());
            found.halves.push(halves.planes());
        };
        each_chunk(x.len(), &mut self.found, |range, found| {
            found.clearances.clear();
            found.touches.clear();
            found.halves.clear();
            for i in range {
                one(i, found);
            }
        });
        self.point_collider.clear();
        self.touches.clear();
        self.halves.clear();
        for part in &self.found {
            self.point_collider.extend_from_slice(&part.clearances);
            self.touches.append(&part.touches);
            self.halves.append(&part.halves);
        }
    }

    /// Per surface triangle: the nearest sharp collider feature (capped at `reach`), and the
    /// feature pairs it may touch before the next detection, with how far each feature
    /// point moves in the step of length `dt`.
    pub(super) fn detect_features(&mut self, model: &Model, x: &[Vec3], reach: f64, dt: f64) {
        let triangles = &self.topology.triangles;
        self.pairs.clear();
        if !model.colliders.iter().any(|c| c.shape.has_features()) {
            self.triangle_collider.clear();
            self.triangle_collider
                .resize(triangles.len(), Clearance::new(reach));
            return;
        }
        let scale = &self.scale;
        let (points, touches) = (&self.point_collider, &self.touches);
        each_chunk(triangles.len(), &mut self.features_found, |range, found| {
            // Worked on as the closure's own, not through `found`: the features' sink is a
            // call the compiler cannot see into, and behind a reference each push reloaded
            // the vectors around it.
            let (mut clearances, mut pairs) = (
                std::mem::take(&mut found.clearances),
                std::mem::take(&mut found.pairs),
            );
            clearances.clear();
            pairs.clear();
            for t in range {
                let (tri, s) = triangles[t];
                let [a, b, c] = tri.map(|i| &x[i as usize]);
                let (lo, hi) = bounds_of(&[a, b, c]);
                let h = model.surfaces[s as usize].thickness;
                let mut clearance = Clearance::new(reach);
                // A feature is a point of a collider's surface, so it is at least as far
                // from a corner as the nearest surface point is, and at least that less the
                // triangle's size from the triangle: a triangle whose corners all see no
                // surface within the reach plus its size has no feature within the reach
                // (unless a corner is inside something, which its contacts then say).
                let nearest = tri
                    .iter()
                    .map(|&i| points[i as usize].nearest)
                    .fold(0.0, f64::max);
                let size = (a - b).norm().max((b - c).norm()).max((c - a).norm());
                let felt = tri.iter().any(|&i| !touches.is_empty_at(i as usize));
                if !felt && nearest - size >= reach {
                    clearances.push(clearance);
                    continue;
                }
                for slot in model.colliders.iter().filter(|c| c.shape.has_features()) {
                    let (k, mu) = collider_law(
                        &slot.response,
                        tri.iter().map(|&i| scale[i as usize]).fold(0.0, f64::max),
                    );
                    slot.shape
                        .features(&lo.add_scalar(-reach), &hi.add_scalar(reach), &mut |f| {
                            // The boxes' distance bounds the feature's from below: a feature
                            // no nearer than what is already known, and not felt, changes
                            // nothing.
                            let (flo, fhi) = f.bounds();
                            let apart = (0..3)
                                .map(|k| (flo[k] - hi[k]).max(lo[k] - fhi[k]).max(0.0).powi(2))
                                .sum::<f64>()
                                .sqrt();
                            if apart >= clearance.nearest && apart > FELT * h {
                                return;
                            }
                            let (anchor, w) = feature_triangle(&f, a, b, c);
                            let d = (a * w[0] + b * w[1] + c * w[2] - anchor).norm();
                            clearance.see(d, d <= FELT * h);
                            if d <= FELT * h {
                                let carry = slot.shape.velocity(&anchor) * dt;
                                pairs.push(Pair {
                                    sides: Sides::Feature(anchor, carry),
                                    ids: [tri[0], tri[1], tri[2], u32::MAX],
                                    h,
                                    k,
                                    mu,
                                });
                            }
                        });
                }
                clearances.push(clearance);
            }
            *found = FeaturesFound { clearances, pairs };
        });
        self.triangle_collider.clear();
        for found in &self.features_found {
            self.triangle_collider.extend_from_slice(&found.clearances);
            self.pairs.extend_from_slice(&found.pairs);
        }
    }
}
