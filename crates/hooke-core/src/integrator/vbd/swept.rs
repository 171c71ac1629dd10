//! How near the particles and surfaces are to a moving collider, which sets how far block
//! descent may let the collider jump at once (the swept step, docs/physics.md §4.1).

use super::cells::{bounds_of, per_chunk};
use crate::contact::proximity::feature_triangle;
use crate::model::Model;
use crate::particles::Particles;

/// The least distance from a free particle, or from a triangle of a surface, to collider
/// `k` at its current pose, capped at `reach`. A particle already inside counts as far:
/// a jump cannot make it more inside than staying does, and its contact pushes it out.
///
/// A least distance is the same whatever order its candidates come in, so the search runs
/// over fixed chunks in parallel, and each search reaches only as far as the least gap its
/// chunk has found yet (by a margin that covers the rounding of a contact's depth): a
/// primitive farther away cannot lower it. The swept step asks this before every part, with
/// a reach of twice the collider's sweep (a table turning at 1 rev/s: 10 cm), where asking
/// every triangle for every feature within the reach was half of the step's time.
pub(crate) fn collider_gap(model: &Model, p: &Particles, k: usize, reach: f64) -> f64 {
    let shape = &model.colliders[k].shape;
    let margin = 1e-9 * reach;
    let least = |gaps: Vec<f64>| gaps.into_iter().fold(reach, f64::min);
    let particles = least(per_chunk(p.x.len(), |range| {
        let mut gap = reach;
        for i in range {
            let x = &p.x[i];
            let near = gap + margin;
            if p.is_pinned(i) || !shape.may_touch(&x.add_scalar(-near), &x.add_scalar(near), 0.0) {
                continue;
            }
            shape.contacts_within(x, reach, &mut |c| {
                let d = reach - c.depth;
                if d >= 0.0 {
                    gap = gap.min(d);
                }
            });
        }
        gap
    }));
    if !shape.has_features() {
        return particles;
    }
    let triangles: Vec<[u32; 3]> = model
        .surfaces
        .iter()
        .flat_map(|s| s.triangles.iter().copied())
        .collect();
    let features = least(per_chunk(triangles.len(), |range| {
        let mut gap = particles;
        for tri in &triangles[range] {
            let [a, b, c] = tri.map(|i| &p.x[i as usize]);
            let (lo, hi) = bounds_of(&[a, b, c]);
            let near = gap + margin;
            shape.features(&lo.add_scalar(-near), &hi.add_scalar(near), &mut |f| {
                let (anchor, w) = feature_triangle(&f, a, b, c);
                gap = gap.min((a * w[0] + b * w[1] + c * w[2] - anchor).norm());
            });
        }
        gap
    }));
    particles.min(features)
}
