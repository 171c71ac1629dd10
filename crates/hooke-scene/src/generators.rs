//! Particle layouts and their spring topologies: chains, cloth grids and jelly lattices.
//!
//! All three are one routine: a chain is an `n × 1 × 1` lattice and a grid an `n × 1 × m`
//! one, so the families of springs (and their order) are defined once.

use hooke_core::{SpringKind, Vec3};

/// A spring of a generated topology, before stiffness is attached: local indices and the rest
/// length in the undeformed shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edge {
    /// First particle (index within the body).
    pub i: u32,
    /// Second particle.
    pub j: u32,
    /// Rest length in metres.
    pub rest: f64,
    /// Family.
    pub kind: SpringKind,
}

/// Pairs of corner offsets joined by shear springs: face diagonals (two per unit square of
/// each axis plane) and body diagonals (four per unit cube).
const SHEAR: [([usize; 3], [usize; 3]); 10] = [
    ([0, 0, 0], [1, 1, 0]),
    ([1, 0, 0], [0, 1, 0]),
    ([0, 0, 0], [1, 0, 1]),
    ([1, 0, 0], [0, 0, 1]),
    ([0, 0, 0], [0, 1, 1]),
    ([0, 1, 0], [0, 0, 1]),
    ([0, 0, 0], [1, 1, 1]),
    ([1, 0, 0], [0, 1, 1]),
    ([0, 1, 0], [1, 0, 1]),
    ([0, 0, 1], [1, 1, 0]),
];

/// A box of `size[0] × size[1] × size[2]` particles, spacing `h`, index `(i n1 + j) n2 + k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lattice {
    /// Particles along each axis.
    pub size: [usize; 3],
}

impl Lattice {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.size.iter().product()
    }

    /// Whether the lattice has no particles.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Index of particle `(i, j, k)`.
    pub fn index(&self, [i, j, k]: [usize; 3]) -> usize {
        (i * self.size[1] + j) * self.size[2] + k
    }

    /// Local positions at spacing `h`, in index order.
    pub fn positions(&self, h: f64) -> Vec<Vec3> {
        let [a, b, c] = self.size;
        let mut out = Vec::with_capacity(self.len());
        for i in 0..a {
            for j in 0..b {
                for k in 0..c {
                    out.push(Vec3::new(i as f64 * h, j as f64 * h, k as f64 * h));
                }
            }
        }
        out
    }

    /// The springs of one family. Rest lengths are `h √(di² + dj² + dk²)` from the integer
    /// offsets, the undeformed lattice's distances (`h`, `√2 h`, `√3 h`, `2 h`).
    pub fn edges(&self, kind: SpringKind, h: f64) -> Vec<Edge> {
        let mut out = Vec::with_capacity(self.edge_count(kind));
        for (a, b) in offsets(kind) {
            let span = [0, 1, 2].map(|d| a[d].max(b[d]));
            if (0..3).any(|d| span[d] >= self.size[d]) {
                continue;
            }
            let d2: usize = (0..3).map(|d| a[d].abs_diff(b[d]).pow(2)).sum();
            let rest = (d2 as f64).sqrt() * h;
            for i in 0..self.size[0] - span[0] {
                for j in 0..self.size[1] - span[1] {
                    for k in 0..self.size[2] - span[2] {
                        let p = self.index([i + a[0], j + a[1], k + a[2]]) as u32;
                        let q = self.index([i + b[0], j + b[1], k + b[2]]) as u32;
                        out.push(Edge {
                            i: p,
                            j: q,
                            rest,
                            kind,
                        });
                    }
                }
            }
        }
        out
    }
}

impl Lattice {
    /// How many springs [`Lattice::edges`] gives for `kind`, without making them (saturating
    /// at `usize::MAX` for sizes no machine could build).
    ///
    /// ```
    /// use hooke_scene::generators::Lattice;
    /// use hooke_core::SpringKind;
    /// let cube = Lattice { size: [8, 8, 8] };
    /// assert_eq!(cube.edge_count(SpringKind::Shear), cube.edges(SpringKind::Shear, 1.0).len());
    /// ```
    pub fn edge_count(&self, kind: SpringKind) -> usize {
        offsets(kind)
            .iter()
            .map(|(a, b)| {
                (0..3)
                    .map(|d| self.size[d].saturating_sub(a[d].max(b[d])))
                    .fold(1usize, usize::saturating_mul)
            })
            .fold(0usize, usize::saturating_add)
    }
}

/// The corner offsets joined by the springs of one family.
fn offsets(kind: SpringKind) -> Vec<([usize; 3], [usize; 3])> {
    match kind {
        SpringKind::Structural => (0..3).map(|axis| ([0; 3], unit(axis, 1))).collect(),
        SpringKind::Shear => SHEAR.to_vec(),
        SpringKind::Bend => (0..3).map(|axis| ([0; 3], unit(axis, 2))).collect(),
        SpringKind::Other => Vec::new(),
    }
}

fn unit(axis: usize, length: usize) -> [usize; 3] {
    let mut v = [0; 3];
    v[axis] = length;
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count(size: [usize; 3], kind: SpringKind) -> usize {
        let lattice = Lattice { size };
        let n = lattice.edges(kind, 1.0).len();
        assert_eq!(lattice.edge_count(kind), n, "{size:?} {kind:?}");
        n
    }

    #[test]
    fn jello_lattice_has_the_course_spring_counts() {
        let s = [8, 8, 8];
        assert_eq!(count(s, SpringKind::Structural), 1344);
        assert_eq!(count(s, SpringKind::Shear), 3724);
        assert_eq!(count(s, SpringKind::Bend), 1152);
    }

    #[test]
    fn cloth_grid_has_the_workload_spring_counts() {
        let n = 64;
        let s = [n, 1, n];
        assert_eq!(count(s, SpringKind::Structural), 2 * n * (n - 1));
        assert_eq!(count(s, SpringKind::Shear), 2 * (n - 1) * (n - 1));
        assert_eq!(count(s, SpringKind::Bend), 2 * n * (n - 2));
    }

    #[test]
    fn rest_lengths_are_the_undeformed_distances() {
        let h = 1.0 / 7.0;
        let lattice = Lattice { size: [8, 8, 8] };
        let x = lattice.positions(h);
        for kind in [SpringKind::Structural, SpringKind::Shear, SpringKind::Bend] {
            for e in lattice.edges(kind, h) {
                let d = (x[e.i as usize] - x[e.j as usize]).norm();
                assert!((d - e.rest).abs() < 1e-15, "{kind:?} {e:?} {d}");
            }
        }
    }

    #[test]
    fn a_chain_has_only_axis_springs() {
        assert_eq!(count([5, 1, 1], SpringKind::Structural), 4);
        assert_eq!(count([5, 1, 1], SpringKind::Shear), 0);
        assert_eq!(count([5, 1, 1], SpringKind::Bend), 3);
    }
}
