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
/// chunk has found yet (by a margin that covers the rounding of a distance), never farther
/// than the reach: a primitive farther away cannot lower it, and none the whole reach's
/// search would miss is met. The swept step asks this before every part, with
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
            let near = (gap + margin).min(reach);
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
    let mut gap = particles;
    for surface in &model.surfaces {
        let triangles = &surface.triangles;
        gap = gap.min(least(per_chunk(triangles.len(), |range| {
            let mut gap = gap;
            for tri in &triangles[range] {
                let [a, b, c] = tri.map(|i| &p.x[i as usize]);
                let (lo, hi) = bounds_of(&[a, b, c]);
                let near = (gap + margin).min(reach);
                shape.features(&lo.add_scalar(-near), &hi.add_scalar(near), &mut |f| {
                    let (anchor, w) = feature_triangle(&f, a, b, c);
                    gap = gap.min((a * w[0] + b * w[1] + c * w[2] - anchor).norm());
                });
            }
            gap
        })));
    }
    gap
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collider::response::Response;
    use crate::collider::{Collider, Contact, Feature};
    use crate::contact::exclusion::tests::sheet;
    use crate::model::ColliderSlot;
    use crate::particles::Vec3;

    /// A ball of radius 0.3 at the origin, with straight spikes standing out of it: the
    /// spikes are its features, handed out only where their boxes meet the query's (as a
    /// mesh's BVH hands them out), so that a search that reaches too little misses them.
    #[derive(Debug)]
    struct Spiky(Vec<[Vec3; 2]>);

    const RADIUS: f64 = 0.3;

    impl Collider for Spiky {
        fn name(&self) -> String {
            "spiky ball".into()
        }

        fn contacts(&self, p: &Vec3, sink: &mut dyn FnMut(Contact)) {
            self.contacts_within(p, 0.0, sink);
        }

        fn contacts_within(&self, p: &Vec3, margin: f64, sink: &mut dyn FnMut(Contact)) {
            let r = p.norm();
            if r - RADIUS < margin && r > 0.0 {
                let normal = p / r;
                sink(Contact {
                    depth: margin - (r - RADIUS),
                    normal,
                    point: normal * RADIUS,
                });
            }
        }

        fn may_touch(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> bool {
            let nearest = Vec3::zeros().sup(lo).inf(hi);
            nearest.norm() <= RADIUS + 0.2 + margin
        }

        fn features(&self, lo: &Vec3, hi: &Vec3, sink: &mut dyn FnMut(Feature)) {
            for s in &self.0 {
                let f = Feature::Segment(*s);
                let (flo, fhi) = f.bounds();
                if (0..3).all(|k| flo[k] <= hi[k] && lo[k] <= fhi[k]) {
                    sink(f);
                }
            }
        }

        fn has_features(&self) -> bool {
            true
        }
    }

    /// A fixed pseudo-random number in `[-1, 1)`.
    fn jitter(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// The gap measured against every particle's contacts and every triangle's features,
    /// with no pruning, in order.
    fn every_pair(model: &Model, p: &Particles, k: usize, reach: f64) -> f64 {
        let shape = &model.colliders[k].shape;
        let mut gap = reach;
        for (i, x) in p.x.iter().enumerate() {
            if !p.is_pinned(i) {
                shape.contacts_within(x, reach, &mut |c| {
                    let d = reach - c.depth;
                    if d >= 0.0 {
                        gap = gap.min(d);
                    }
                });
            }
        }
        let far = Vec3::repeat(1e3);
        for tri in &model.surfaces[0].triangles {
            let [a, b, c] = tri.map(|i| &p.x[i as usize]);
            shape.features(&-far, &far, &mut |f| {
                let (anchor, w) = feature_triangle(&f, a, b, c);
                gap = gap.min((a * w[0] + b * w[1] + c * w[2] - anchor).norm());
            });
        }
        gap
    }

    /// The pruned, parallel search gives the least gap to the bit, wherever the nearest
    /// primitive is (a particle, a triangle's face over a spike, or nothing within the
    /// reach), on sheets of a few thousand particles in several chunks.
    #[test]
    fn the_gap_is_the_least_over_every_pair() {
        let mut state = 7u64;
        let spikes: Vec<[Vec3; 2]> = (0..60)
            .map(|_| {
                let d = Vec3::new(jitter(&mut state), jitter(&mut state), jitter(&mut state))
                    .normalize();
                [d * RADIUS, d * (RADIUS + 0.15)]
            })
            .collect();
        let n = 48;
        let mut found = 0;
        for (height, spacing) in [(0.36, 0.02), (0.42, 0.015), (0.6, 0.03), (2.0, 0.02)] {
            let (mut model, x) = sheet(
                n,
                0.002,
                |_, _| false,
                |i, j| {
                    Vec3::new(
                        (i as f64 - n as f64 / 2.0) * spacing + 0.3 * spacing * jitter(&mut state),
                        height + 0.05 * jitter(&mut state),
                        (j as f64 - n as f64 / 2.0) * spacing + 0.3 * spacing * jitter(&mut state),
                    )
                },
            );
            model.colliders.push(ColliderSlot {
                shape: Box::new(Spiky(spikes.clone())),
                response: Response::Stick,
            });
            let mut p = Particles::default();
            for x in x {
                p.push(x, Vec3::zeros(), 1e-3);
            }
            p.pin(0);
            for reach in [0.01, 0.1, 0.5] {
                let want = every_pair(&model, &p, 0, reach);
                assert_eq!(
                    collider_gap(&model, &p, 0, reach).to_bits(),
                    want.to_bits(),
                    "sheet at {height} m, reach {reach}"
                );
                found += usize::from(want < reach);
            }
        }
        // Most cases find something within the reach, not only the reach itself.
        assert!(found >= 6, "{found}");
    }
}
