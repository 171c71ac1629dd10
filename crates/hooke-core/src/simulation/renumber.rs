//! Renumbering particles: the solver's speed depends on the order particles are numbered
//! in, as their springs read and write the arrays at both ends. A mesh numbered row by row
//! has springs whose ends advance together, which the layout runs as contiguous loads and
//! stores (see `kernel/run_loop.rs`); a mesh that arrives numbered at random scatters every
//! access over the whole arrays. [`Renumbering::by_locality`] finds a row-by-row order from
//! where the particles are; [`crate::Simulation::renumber`] applies one.

use crate::forces::spring::Spring;
use crate::model::Model;
use crate::particles::{Particles, Vec3};
use std::ops::Range;

/// The part of `range` below `n` (a body range past the particles names none of them).
fn within(range: &Range<usize>, n: usize) -> Range<usize> {
    range.start.min(n)..range.end.min(n)
}

/// A renumbering of `n` particles: particle `old` becomes `new_index(old)`.
///
/// ```
/// use hooke_core::Renumbering;
/// let r = Renumbering::new(vec![2, 0, 1]).expect("a permutation");
/// assert_eq!(r.old_index(0), 2);
/// assert_eq!(r.new_index(2), 0);
/// assert!(Renumbering::new(vec![0, 0, 1]).is_none());
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Renumbering {
    old_of_new: Vec<u32>,
    new_of_old: Vec<u32>,
}

impl Renumbering {
    /// The renumbering that gives new particle `k` the old particle `old_of_new[k]`; `None`
    /// unless every index below the length appears once.
    pub fn new(old_of_new: Vec<u32>) -> Option<Self> {
        let mut new_of_old = vec![u32::MAX; old_of_new.len()];
        for (new, &old) in old_of_new.iter().enumerate() {
            let slot = new_of_old.get_mut(old as usize)?;
            if *slot != u32::MAX {
                return None;
            }
            *slot = new as u32;
        }
        Some(Self {
            old_of_new,
            new_of_old,
        })
    }

    /// Leaves `n` particles as they are.
    pub fn identity(n: usize) -> Self {
        let order: Vec<u32> = (0..n as u32).collect();
        Self {
            old_of_new: order.clone(),
            new_of_old: order,
        }
    }

    /// Particles renumbered at random within each range of `bodies` (others keep their
    /// numbers), by `seed`: the same seed gives the same numbering. For benchmarks and tests
    /// of meshes that arrive unordered.
    pub fn shuffled(n: usize, bodies: &[Range<usize>], seed: u64) -> Self {
        let mut state = seed ^ 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            // xorshift64*: a fixed, portable sequence.
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            state.wrapping_mul(0x2545_f491_4f6c_dd1d)
        };
        let mut order: Vec<u32> = (0..n as u32).collect();
        for body in bodies {
            let part = &mut order[within(body, n)];
            for k in (1..part.len()).rev() {
                part.swap(k, (next() % (k as u64 + 1)) as usize);
            }
        }
        Self::new(order).expect("a shuffle is a permutation")
    }

    /// An order with locality, within each range of `bodies` (others keep their numbers):
    /// particles sorted by their cell on a grid of half the median rest length of the
    /// body's springs, along the axes from the longest extent of the body to the shortest.
    /// A grid mesh, however numbered, comes out row by row (exactly as a generator numbers
    /// it when that numbers the longest axis slowest); any mesh comes out in slabs, each
    /// spring's ends near each other in the arrays.
    pub fn by_locality(x: &[Vec3], springs: &[Spring], bodies: &[Range<usize>]) -> Self {
        let mut order: Vec<u32> = (0..x.len() as u32).collect();
        for body in bodies {
            let body = &within(body, x.len());
            let mut rest: Vec<f64> = springs
                .iter()
                .filter(|s| body.contains(&(s.i as usize)) && body.contains(&(s.j as usize)))
                .map(|s| s.rest)
                .filter(|r| r.is_finite() && *r > 0.0)
                .collect();
            let cell = if rest.is_empty() {
                1.0
            } else {
                let mid = rest.len() / 2;
                0.5 * *rest.select_nth_unstable_by(mid, f64::total_cmp).1
            };
            let points = &x[body.clone()];
            let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
            for p in points {
                lo = lo.inf(p);
                hi = hi.sup(p);
            }
            let mut axes = [0, 1, 2];
            // Longest extent first; equal extents keep x, y, z order.
            axes.sort_by(|&a, &b| (hi[b] - lo[b]).total_cmp(&(hi[a] - lo[a])));
            let key = |p: &Vec3| axes.map(|a| ((p[a] - lo[a]) / cell + 0.5).floor() as i64);
            order[body.clone()].sort_by_key(|&k| (key(&x[k as usize]), k));
        }
        Self::new(order).expect("a sort is a permutation")
    }

    /// The number of particles.
    pub fn len(&self) -> usize {
        self.old_of_new.len()
    }

    /// Whether it renumbers no particle at all (zero particles).
    pub fn is_empty(&self) -> bool {
        self.old_of_new.is_empty()
    }

    /// The new number of particle `old`.
    pub fn new_index(&self, old: usize) -> usize {
        self.new_of_old[old] as usize
    }

    /// The old number of particle `new`.
    pub fn old_index(&self, new: usize) -> usize {
        self.old_of_new[new] as usize
    }

    /// This renumbering followed by `next`.
    pub fn then(&self, next: &Renumbering) -> Renumbering {
        let order = (0..self.len())
            .map(|k| self.old_of_new[next.old_index(k)])
            .collect();
        Self::new(order).expect("a composition of permutations is one")
    }

    fn map(&self, i: u32) -> u32 {
        self.new_of_old[i as usize]
    }

    /// `particles` renumbered.
    pub(crate) fn particles(&self, p: &Particles) -> Particles {
        let pick = |k: usize| self.old_index(k);
        let n = self.len();
        Particles {
            x: (0..n).map(|k| p.x[pick(k)]).collect(),
            v: (0..n).map(|k| p.v[pick(k)]).collect(),
            mass: (0..n).map(|k| p.mass[pick(k)]).collect(),
            inv_mass: (0..n).map(|k| p.inv_mass[pick(k)]).collect(),
        }
    }

    /// Renumbers every particle index `model` holds: springs, attachments, keyframed pins,
    /// surfaces' and air's triangles (a surface's range stays its own, as renumberings keep
    /// bodies).
    pub(crate) fn model(&self, model: &mut Model) {
        for s in &mut model.springs {
            (s.i, s.j) = (self.map(s.i), self.map(s.j));
        }
        for a in &mut model.attachments {
            a.particle = self.new_index(a.particle);
        }
        for m in &mut model.pin_motions {
            for i in &mut m.particles {
                *i = self.map(*i);
            }
        }
        let triangles = model
            .surfaces
            .iter_mut()
            .map(|s| &mut s.triangles)
            .chain(model.aero.iter_mut().map(|a| &mut a.triangles));
        for list in triangles {
            for t in list {
                *t = t.map(|i| self.map(i));
            }
        }
    }

    /// Whether it keeps every particle of each range within that range.
    pub(crate) fn keeps(&self, ranges: impl IntoIterator<Item = Range<usize>>) -> bool {
        ranges
            .into_iter()
            .all(|r| r.clone().all(|old| r.contains(&self.new_index(old))))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_permutations_are_renumberings_and_they_compose() {
        assert!(Renumbering::new(vec![1, 2]).is_none());
        assert!(Renumbering::new(vec![1, 1]).is_none());
        let all = std::iter::once(0..50).collect::<Vec<_>>();
        let a = Renumbering::shuffled(50, &all, 3);
        let b = Renumbering::shuffled(50, &all, 4);
        assert_ne!(a, b);
        let ab = a.then(&b);
        for old in 0..50 {
            assert_eq!(a.old_index(a.new_index(old)), old);
            assert_eq!(ab.new_index(old), b.new_index(a.new_index(old)));
        }
    }

    #[test]
    fn shuffles_keep_bodies_and_locality_undoes_them() {
        // Two bodies: a 12 × 9 sheet in the x-z plane and a 5 × 4 × 3 block, numbered as a
        // generator would (last axis fastest, the longest slowest), springs between grid
        // neighbours.
        let mut x = Vec::new();
        for i in 0..12 {
            for k in 0..9 {
                x.push(Vec3::new(i as f64 * 0.1, 1.0, k as f64 * 0.1));
            }
        }
        for i in 0..5 {
            for j in 0..4 {
                for k in 0..3 {
                    x.push(Vec3::new(
                        5.0 + i as f64 * 0.2,
                        j as f64 * 0.2,
                        k as f64 * 0.2,
                    ));
                }
            }
        }
        let bodies = [0..108, 108..168];
        let springs: Vec<Spring> = (0..x.len())
            .flat_map(|a| (a + 1..x.len()).map(move |b| (a, b)))
            .filter(|&(a, b)| {
                let same = bodies.iter().any(|r| r.contains(&a) && r.contains(&b));
                same && (x[a] - x[b]).norm() < 0.25
            })
            .map(|(a, b)| Spring {
                i: a as u32,
                j: b as u32,
                rest: (x[a] - x[b]).norm(),
                ks: 1.0,
                kd: 0.0,
                kind: crate::SpringKind::Other,
            })
            .collect();
        // Ranges past the particles are cut at their end, not a panic.
        let past = [1000..1200, 1300..1400];
        assert_eq!(Renumbering::shuffled(4, &past, 1), Renumbering::identity(4));
        assert_eq!(
            Renumbering::by_locality(&x[..4], &[], &past),
            Renumbering::identity(4)
        );
        let shuffled = Renumbering::shuffled(x.len(), &bodies, 11);
        assert!(shuffled.keeps(bodies.iter().cloned()));
        assert_ne!(shuffled, Renumbering::identity(x.len()));
        let p = Particles {
            x: x.clone(),
            v: vec![Vec3::zeros(); x.len()],
            mass: vec![1.0; x.len()],
            inv_mass: vec![1.0; x.len()],
        };
        let mut model = Model {
            springs: springs.clone(),
            ..Model::default()
        };
        let moved = shuffled.particles(&p);
        shuffled.model(&mut model);
        let local = Renumbering::by_locality(&moved.x, &model.springs, &bodies);
        assert_eq!(shuffled.then(&local), Renumbering::identity(x.len()));
    }
}
