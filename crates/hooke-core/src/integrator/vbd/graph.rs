//! The springs seen from each particle, and a colouring of the particles such that no two of
//! one colour share a spring: the order in which block descent visits them.

use crate::model::Model;
use crate::particles::Particles;

/// One spring seen from one of its ends.
#[derive(Clone, Copy, Debug)]
pub(super) struct Neighbour {
    /// The particle at the other end.
    pub(super) other: u32,
    pub(super) rest: f64,
    pub(super) ks: f64,
    pub(super) kd: f64,
}

/// Per-particle spring lists and the colouring, built once per model.
#[derive(Clone, Debug, Default)]
pub(super) struct Graph {
    /// The particle and spring counts it was built for.
    built_for: (usize, usize),
    /// Particle `i`'s neighbours are `neighbours[start[i]..start[i + 1]]`, in spring order.
    start: Vec<u32>,
    neighbours: Vec<Neighbour>,
    /// The free (unpinned) particles of each colour, in increasing index.
    pub(super) colours: Vec<Vec<u32>>,
    /// Per particle: `m / dt²`-free stiffness scale, the sum of its springs' `ks`.
    pub(super) stiffness: Vec<f64>,
    /// Whether the colouring also separates the last detection's contact pairs.
    pub(super) coloured_with_contacts: bool,
}

impl Graph {
    /// Whether it was built for `particles` particles and `springs` springs.
    pub(super) fn fits(&self, particles: usize, springs: usize) -> bool {
        self.built_for == (particles, springs) && !self.start.is_empty()
    }

    /// Builds the lists and a greedy colouring in particle order, which depends on the model
    /// alone (never on threads).
    pub(super) fn new(model: &Model, p: &Particles) -> Self {
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
            rest: 0.0,
            ks: 0.0,
            kd: 0.0,
        };
        let mut neighbours = vec![empty; start[n] as usize];
        let mut stiffness = vec![0.0; n];
        for s in &model.springs {
            for (a, b) in [(s.i, s.j), (s.j, s.i)] {
                let a = a as usize;
                neighbours[cursor[a] as usize] = Neighbour {
                    other: b,
                    rest: s.rest,
                    ks: s.ks,
                    kd: s.kd,
                };
                cursor[a] += 1;
                stiffness[a] += s.ks;
            }
        }
        let mut graph = Self {
            built_for: (n, model.springs.len()),
            start,
            neighbours,
            colours: Vec::new(),
            stiffness,
            coloured_with_contacts: false,
        };
        graph.colour(p, |_, _| {});
        graph
    }

    /// Colours the free particles greedily in index order: each takes the lowest colour
    /// that none of its earlier spring neighbours, nor the earlier particles `contacts` names
    /// for it, has. Depends on the model and the contacts alone, never on threads.
    pub(super) fn colour(&mut self, p: &Particles, contacts: impl Fn(usize, &mut dyn FnMut(u32))) {
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
    }

    /// The springs of particle `i`.
    #[inline]
    pub(super) fn of(&self, i: usize) -> &[Neighbour] {
        &self.neighbours[self.start[i] as usize..self.start[i + 1] as usize]
    }
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
