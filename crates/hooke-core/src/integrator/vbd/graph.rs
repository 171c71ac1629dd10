//! The springs seen from each particle, and a colouring of the particles such that no two of
//! one colour share a spring: the order in which block descent visits them.

use crate::model::Model;
use crate::particles::Particles;

/// One spring seen from one of its ends: 16 bytes, its coefficients shared with every
/// spring that has the same (a cloth's springs come in a few kinds).
#[derive(Clone, Copy, Debug)]
pub(in crate::integrator) struct Neighbour {
    /// The particle at the other end.
    pub(in crate::integrator) other: u32,
    /// Its `(ks, kd)` in the graph's table ([`Graph::law`]).
    law: u32,
    pub(in crate::integrator) rest: f64,
}

/// Per-particle spring lists and the colouring, built once per model.
#[derive(Clone, Debug, Default)]
pub(in crate::integrator) struct Graph {
    /// The particle and spring counts it was built for.
    built_for: (usize, usize),
    /// Particle `i`'s neighbours are `neighbours[start[i]..start[i + 1]]`, in spring order.
    start: Vec<u32>,
    neighbours: Vec<Neighbour>,
    /// The distinct `[ks, kd]` of the springs, in the order they first come.
    laws: Vec<[f64; 2]>,
    /// The free (unpinned) particles of each colour, in increasing index.
    pub(in crate::integrator) colours: Vec<Vec<u32>>,
    /// Per particle: `m / dt²`-free stiffness scale, the sum of its springs' `ks`.
    pub(in crate::integrator) stiffness: Vec<f64>,
    /// Which colouring `colours` is: a number no other colouring in this process had, so
    /// that what is laid out for one (`lanes/`) knows when it is stale.
    pub(in crate::integrator) colouring: u64,
    /// Whether the colouring also separates the last detection's contact pairs.
    pub(in crate::integrator) coloured_with_contacts: bool,
    /// The bodies that may translate as a whole: the particles of each connected set of
    /// springs holding no pinned particle, in increasing index (the coarse correction's
    /// groups, docs/physics.md §4.1).
    pub(in crate::integrator) free_bodies: Vec<Vec<u32>>,
    /// Per particle: the index of its free body, or `u32::MAX`.
    pub(in crate::integrator) body_of: Vec<u32>,
}

impl Graph {
    /// Whether it was built for `particles` particles and `springs` springs.
    pub(in crate::integrator) fn fits(&self, particles: usize, springs: usize) -> bool {
        self.built_for == (particles, springs) && !self.start.is_empty()
    }

    /// Builds the lists and a greedy colouring in particle order, which depends on the model
    /// alone (never on threads).
    pub(in crate::integrator) fn new(model: &Model, p: &Particles) -> Self {
        let n = p.len();
        let mut count = vec![0u32; n + 1];
        for s in &model.springs {
            count[s.i as usize] += 1;
            count[s.j as usize] += 1;
        }
        let mut start = vec![0u32; n + 1];
        for i in 0..n {
            start[i + 1] = start[i] + count[i];
        }
        let mut cursor = start.clone();
        let empty = Neighbour {
            other: 0,
            law: 0,
            rest: 0.0,
        };
        let mut neighbours = vec![empty; start[n] as usize];
        let mut stiffness = vec![0.0; n];
        let (mut laws, mut index) = (Vec::new(), std::collections::HashMap::new());
        for s in &model.springs {
            let law = *index
                .entry([s.ks.to_bits(), s.kd.to_bits()])
                .or_insert_with(|| {
                    laws.push([s.ks, s.kd]);
                    laws.len() as u32 - 1
                });
            for (a, b) in [(s.i, s.j), (s.j, s.i)] {
                let a = a as usize;
                neighbours[cursor[a] as usize] = Neighbour {
                    other: b,
                    law,
                    rest: s.rest,
                };
                cursor[a] += 1;
                stiffness[a] += s.ks;
            }
        }
        let mut graph = Self {
            built_for: (n, model.springs.len()),
            start,
            neighbours,
            laws,
            colours: Vec::new(),
            colouring: 0,
            stiffness,
            coloured_with_contacts: false,
            free_bodies: Vec::new(),
            body_of: vec![u32::MAX; n],
        };
        graph.free_bodies = free_bodies(model, p);
        for (b, body) in graph.free_bodies.iter().enumerate() {
            for &i in body {
                graph.body_of[i as usize] = b as u32;
            }
        }
        graph.colour(p, |_, _| {});
        graph
    }

    /// Colours the free particles greedily in index order: each takes the lowest colour
    /// that none of its earlier spring neighbours, nor the earlier particles `contacts` names
    /// for it, has. Depends on the model and the contacts alone, never on threads.
    pub(in crate::integrator) fn colour(
        &mut self,
        p: &Particles,
        contacts: impl Fn(usize, &mut dyn FnMut(u32)),
    ) {
        let n = p.len();
        let mut colour = vec![u32::MAX; n];
        for c in &mut self.colours {
            c.clear();
        }
        let mut used = 0;
        let mut taken: Vec<bool> = Vec::new();
        for i in 0..n {
            if p.is_pinned(i) {
                continue;
            }
            taken.clear();
            taken.resize(used + 1, false);
            let mut take = |j: u32| {
                let c = colour[j as usize];
                if (c as usize) < taken.len() {
                    taken[c as usize] = true;
                }
            };
            for nb in self.of(i) {
                take(nb.other);
            }
            contacts(i, &mut take);
            let c = taken.iter().position(|t| !t).unwrap_or(used);
            if c == used {
                used += 1;
                if self.colours.len() < used {
                    self.colours.push(Vec::new());
                }
            }
            colour[i] = c as u32;
            self.colours[c].push(i as u32);
        }
        self.colours.truncate(used);
        static COLOURINGS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
        self.colouring = COLOURINGS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// Where particle `i`'s springs start in the list of every particle's springs.
    #[inline]
    pub(in crate::integrator) fn first(&self, i: usize) -> usize {
        self.start[i] as usize
    }

    /// The springs of particle `i`.
    #[inline]
    pub(in crate::integrator) fn of(&self, i: usize) -> &[Neighbour] {
        &self.neighbours[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// A neighbour's spring's stiffness and damping, `(ks, kd)`.
    #[inline]
    pub(in crate::integrator) fn law(&self, nb: &Neighbour) -> (f64, f64) {
        let [ks, kd] = self.laws[nb.law as usize];
        (ks, kd)
    }
}

/// The particles of each connected set of springs with no pinned particle (and more than one
/// particle), each in increasing index, the sets ordered by their lowest index: a function
/// of the model alone.
fn free_bodies(model: &Model, p: &Particles) -> Vec<Vec<u32>> {
    let n = p.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            let up = parent[parent[i as usize] as usize];
            parent[i as usize] = up;
            i = up;
        }
        i
    }
    for s in &model.springs {
        let (a, b) = (root(&mut parent, s.i), root(&mut parent, s.j));
        // The lower index is the root: the result does not depend on the spring order.
        let (lo, hi) = (a.min(b), a.max(b));
        parent[hi as usize] = lo;
    }
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut held = vec![false; n];
    for i in 0..n {
        let r = root(&mut parent, i as u32) as usize;
        members[r].push(i as u32);
        held[r] |= p.is_pinned(i);
    }
    members
        .into_iter()
        .enumerate()
        .filter(|(r, m)| m.len() > 1 && !held[*r])
        .map(|(_, m)| m)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forces::spring::{Spring, SpringKind};
    use crate::particles::Vec3;

    #[test]
    fn no_spring_joins_two_particles_of_one_colour() {
        // A 6×6 grid with structural, shear and bend springs; corner 0 pinned.
        let n = 6;
        let mut p = Particles::default();
        for k in 0..n * n {
            p.push(
                Vec3::new((k % n) as f64, 0.0, (k / n) as f64),
                Vec3::zeros(),
                1.0,
            );
        }
        p.pin(0);
        let mut springs = Vec::new();
        let id = |r: usize, c: usize| (r * n + c) as u32;
        for r in 0..n {
            for c in 0..n {
                for (dr, dc) in [(0, 1), (1, 0), (1, 1), (0, 2), (2, 0)] {
                    if r + dr < n && c + dc < n {
                        springs.push(Spring {
                            i: id(r, c),
                            j: id(r + dr, c + dc),
                            rest: 1.0,
                            ks: 10.0,
                            kd: 0.0,
                            kind: SpringKind::Other,
                        });
                    }
                }
            }
        }
        let model = Model {
            springs: springs.clone(),
            ..Model::default()
        };
        let g = Graph::new(&model, &p);
        let mut colour = vec![usize::MAX; n * n];
        for (c, members) in g.colours.iter().enumerate() {
            for &i in members {
                assert_eq!(
                    colour[i as usize],
                    usize::MAX,
                    "particle {i} coloured twice"
                );
                colour[i as usize] = c;
            }
        }
        assert_eq!(colour[0], usize::MAX, "a pinned particle is never visited");
        assert!(colour[1..].iter().all(|&c| c != usize::MAX));
        for s in &springs {
            let (a, b) = (colour[s.i as usize], colour[s.j as usize]);
            assert!(
                a == usize::MAX || a != b,
                "spring {}-{} within a colour",
                s.i,
                s.j
            );
        }
        assert!(g.colours.len() <= 12, "{} colours", g.colours.len());
        assert_eq!(g.of(0).len(), 5);
    }
}
