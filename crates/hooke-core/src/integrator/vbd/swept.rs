//! How near the particles and surfaces are to a moving collider, which sets how far block
//! descent may let the collider jump at once (the swept step, docs/physics.md §4.1).

use super::cells::bounds_of;
use crate::contact::proximity::feature_triangle;
use crate::model::Model;
use crate::particles::Particles;

/// The least distance from a free particle, or from a triangle of a surface, to collider
/// `k` at its current pose, capped at `reach`. A particle already inside counts as far:
/// a jump cannot make it more inside than staying does, and its contact pushes it out.
pub(crate) fn collider_gap(model: &Model, p: &Particles, k: usize, reach: f64) -> f64 {
    let shape = &model.colliders[k].shape;
    let mut gap = reach;
    for (i, x) in p.x.iter().enumerate() {
        if p.is_pinned(i) || !shape.may_touch(&x.add_scalar(-reach), &x.add_scalar(reach), 0.0) {
            continue;
        }
        shape.contacts_within(x, reach, &mut |c| {
            let d = reach - c.depth;
            if d >= 0.0 {
                gap = gap.min(d);
            }
        });
    }
    if shape.has_features() {
        for tri in model.surfaces.iter().flat_map(|s| &s.triangles) {
            let [a, b, c] = tri.map(|i| &p.x[i as usize]);
            let (lo, hi) = bounds_of(&[a, b, c]);
            shape.features(&lo.add_scalar(-reach), &hi.add_scalar(reach), &mut |f| {
                let (anchor, w) = feature_triangle(&f, a, b, c);
                gap = gap.min((a * w[0] + b * w[1] + c * w[2] - anchor).norm());
            });
        }
    }
    gap
}
