//! The watch on what self-contact skips (docs/physics.md §3.5, "A surface through
//! itself"): the triangle pairs that only a skipped pair could bring through each other,
//! listed once with the exclusion, and after a step whether an edge of one passes through
//! the other.
//!
//! A surface leaves a state without crossings through a crossing only by a particle
//! passing through a triangle or an edge through an edge; a pair that is measured never
//! does (the large steps' bounds keep it apart, and the contact phase at steps within half
//! the thickness: docs/physics.md §3.5). What may is a skipped pair: a
//! particle `v` through a skipped triangle `t`, after which an edge at `v` passes through
//! `t`, or an edge `e` through a skipped edge `f`, after which one of them passes through
//! a triangle of the other. So the pairs watched are each skipped triangle against the
//! triangles at its particle, and the triangles at each skipped edge against those at the
//! other, sharing no particle. Nothing else is looked at, so a surface with nothing
//! skipped costs nothing.

use super::{list, listed};
use crate::particles::Vec3;
use rayon::prelude::*;

/// Triangles (or pairs) per parallel chunk of the check.
const CHUNK: usize = 1024;

/// An edge end nearer a triangle's plane than this, metres, is on it, not through it: a
/// flat sheet's neighbours lie in one plane to rounding, and a crossing is deeper.
const ON_PLANE: f64 = 1e-9;

/// The triangle pairs watched: the triangles' corners, and each pair under its lower
/// index, in index order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Folds {
    triangles: Vec<[u32; 3]>,
    /// Triangle `a`'s watched partners (each above `a`, ascending) are
    /// `partners[start[a]..start[a + 1]]`; `start` is empty when nothing is watched.
    start: Vec<u32>,
    partners: Vec<u32>,
}

/// Whether two triangles share a particle.
fn share(a: &[u32; 3], b: &[u32; 3]) -> bool {
    a.iter().any(|i| b.contains(i))
}

/// The skipped pairs as lists: per particle its skipped triangles, per edge the skipped
/// edges below it, each pair once (each the range `start[i]..start[i + 1]` of `all`).
pub(super) struct Skipped<'a> {
    pub(super) triangle_start: &'a [u32],
    pub(super) triangles: &'a [u32],
    pub(super) edge_start: &'a [u32],
    pub(super) edges: &'a [u32],
}

impl Folds {
    /// The pairs for `triangles` and `edges` (as the exclusion indexes them), with
    /// `at[v]` the triangles holding particle `v` and `skipped` the exclusion's lists.
    pub(super) fn new(
        triangles: &[[u32; 3]],
        edges: &[[u32; 2]],
        at: &[Vec<u32>],
        skipped: &Skipped,
    ) -> Self {
        if skipped.triangles.is_empty() && skipped.edges.is_empty() {
            return Self::default();
        }
        let pair = |a: u32, b: u32| [a.min(b), a.max(b)];
        let skips = |v: u32, t: u32| listed(skipped.triangle_start, skipped.triangles, v, t);
        // Each pair once from each side that lists it, from the first corner that does
        // (a triangle's three corners often skip the same triangle): the list before its
        // sort holds at most twice the pairs.
        let by_particle = (0..at.len()).into_par_iter().flat_map_iter(|v| {
            let v = v as u32;
            let mut out = Vec::new();
            for &t in list(skipped.triangle_start, skipped.triangles, v as usize) {
                let tt = &triangles[t as usize];
                for &a in &at[v as usize] {
                    let ta = &triangles[a as usize];
                    if !share(ta, tt) && !ta.iter().any(|&u| u < v && skips(u, t)) {
                        out.push(pair(a, t));
                    }
                }
            }
            out
        });
        let of_edge = |e: u32| {
            let [a, b] = edges[e as usize];
            at[a as usize]
                .iter()
                .copied()
                .filter(move |&t| triangles[t as usize].contains(&b))
        };
        // A skipped pair of edges adds the triangles at them only where no corner of one
        // skips the other (a sliver's neighbours): within the reach along the edges, an end
        // of one edge is within it of the other's triangles, and the particles' lists hold
        // the pair already.
        let by_edge = (0..edges.len()).into_par_iter().flat_map_iter(|e| {
            let mut out = Vec::new();
            let [a, b] = edges[e];
            for &f in list(skipped.edge_start, skipped.edges, e) {
                let [c, d] = edges[f as usize];
                for t in of_edge(f).filter(|&t| !skips(a, t) && !skips(b, t)) {
                    for s in of_edge(e as u32).filter(|&s| !skips(c, s) && !skips(d, s)) {
                        if !share(&triangles[s as usize], &triangles[t as usize]) {
                            out.push(pair(s, t));
                        }
                    }
                }
            }
            out
        });
        let mut pairs: Vec<[u32; 2]> = by_particle.chain(by_edge).collect();
        pairs.par_sort_unstable();
        pairs.dedup();
        // One index a pair, under its first triangle's: half the memory of the pairs.
        let mut start = Vec::with_capacity(triangles.len() + 1);
        let mut partners = Vec::with_capacity(pairs.len());
        start.push(0);
        for a in 0..triangles.len() as u32 {
            let first = partners.len();
            let rest = &pairs[first..];
            let run = rest.iter().take_while(|p| p[0] == a).count();
            partners.extend(rest[..run].iter().map(|p| p[1]));
            start.push(partners.len() as u32);
        }
        Self {
            triangles: triangles.to_vec(),
            start,
            partners,
        }
    }

    /// Triangle `a`'s watched partners.
    fn partners(&self, a: usize) -> &[u32] {
        &self.partners[self.start[a] as usize..self.start[a + 1] as usize]
    }

    /// The first watched pair (in the lists' order, so the same on any thread count) of
    /// which an edge of one passes through the other at positions `x`: the corners of the
    /// triangle whose edge passes, that edge's two first. `planes` is a buffer kept
    /// between calls.
    pub(crate) fn first_through(&self, x: &[Vec3], planes: &mut Vec<Plane>) -> Option<[u32; 3]> {
        if self.partners.is_empty() {
            return None;
        }
        self.triangles
            .par_iter()
            .with_min_len(CHUNK)
            .map(|t| Plane::of(t, x))
            .collect_into_vec(planes);
        let planes = &planes[..];
        (0..self.triangles.len())
            .into_par_iter()
            // Some sixteen partners a triangle on a fine sheet: chunks of about CHUNK pairs.
            .with_min_len(CHUNK / 16)
            .flat_map_iter(|a| self.partners(a).iter().map(move |&b| (a, b as usize)))
            .find_map_first(|(a, b)| {
                let (ta, tb) = (&self.triangles[a], &self.triangles[b]);
                through((ta, &planes[a]), (tb, &planes[b]), x)
            })
    }

    /// Whether triangles `a` and `b` (as the exclusion indexes them) are a watched pair:
    /// one that only a skipped pair could bring through each other.
    pub(crate) fn watches(&self, a: u32, b: u32) -> bool {
        let (a, b) = (a.min(b), a.max(b));
        !self.start.is_empty() && self.partners(a as usize).binary_search(&b).is_ok()
    }

    /// How many triangle pairs are watched.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.partners.len()
    }
}

/// A triangle's plane: its unit normal (by its corners' order) and its offset along it;
/// NaN for a triangle without an area, which no edge then passes through.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Plane {
    normal: Vec3,
    offset: f64,
}

impl Plane {
    /// The plane of triangle `t` at `x`.
    pub(crate) fn of(t: &[u32; 3], x: &[Vec3]) -> Self {
        let [p, q, r] = t.map(|i| x[i as usize]);
        let n = (q - p).cross(&(r - p));
        let normal = n / n.norm();
        Self {
            normal,
            offset: normal.dot(&p),
        }
    }

    /// The signed distances of triangle `t`'s corners from the plane, metres.
    fn sides(&self, t: &[u32; 3], x: &[Vec3]) -> [f64; 3] {
        t.map(|i| self.normal.dot(&x[i as usize]) - self.offset)
    }
}

/// Whether an edge of one triangle passes through the other, each given with its plane
/// at `x`: the corners of the triangle whose edge passes, that edge's two first.
pub(crate) fn through(
    (ta, pa): (&[u32; 3], &Plane),
    (tb, pb): (&[u32; 3], &Plane),
    x: &[Vec3],
) -> Option<[u32; 3]> {
    // An edge passes through a triangle only if its ends lie on either side of the
    // triangle's plane: three products reject most pairs of a smooth sheet.
    let (sa, sb) = (pb.sides(ta, x), pa.sides(tb, x));
    passes(ta, (tb, pb), sa, x).or_else(|| passes(tb, (ta, pa), sb, x))
}

/// Whether an edge of triangle `a`, its corners at distances `side` from `b`'s plane,
/// passes through the inside of triangle `b`: its ends on either side of the plane, the
/// point where it meets the plane inside all three of `b`'s edges. Gives `a`'s corners
/// with that edge's ends first.
fn passes(
    a: &[u32; 3],
    (b, plane): (&[u32; 3], &Plane),
    side: [f64; 3],
    x: &[Vec3],
) -> Option<[u32; 3]> {
    let above = side.iter().any(|&s| s > ON_PLANE);
    let below = side.iter().any(|&s| s < -ON_PLANE);
    if !(above && below) {
        return None;
    }
    let [p, q, r] = b.map(|i| x[i as usize]);
    let n = plane.normal;
    for k in 0..3 {
        let (s0, s1) = (side[k], side[(k + 1) % 3]);
        if !((s0 > ON_PLANE && s1 < -ON_PLANE) || (s0 < -ON_PLANE && s1 > ON_PLANE)) {
            continue;
        }
        let (u, w) = (x[a[k] as usize], x[a[(k + 1) % 3] as usize]);
        let y = u + (w - u) * (s0 / (s0 - s1));
        let inside = [(p, q), (q, r), (r, p)]
            .iter()
            .all(|(c, d)| n.dot(&(d - c).cross(&(y - c))) > 0.0);
        if inside {
            return Some([a[k], a[(k + 1) % 3], a[(k + 2) % 3]]);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether an edge of `a` passes through `b` (see [`passes`]).
    fn through(a: &[u32; 3], b: &[u32; 3], x: &[Vec3]) -> Option<[u32; 3]> {
        let plane = Plane::of(b, x);
        passes(a, (b, &plane), plane.sides(a, x), x)
    }

    /// Two triangles sharing nothing, the second stood upright through or beside the first.
    fn pair(through: bool) -> (Vec<Vec3>, [u32; 3], [u32; 3]) {
        let lift = if through { -0.5 } else { 0.5 };
        let x = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.2, 0.2, lift),
            Vec3::new(0.2, 0.2, lift + 1.0),
            Vec3::new(0.9, 0.9, lift + 1.0),
        ];
        (x, [0, 1, 2], [3, 4, 5])
    }

    #[test]
    fn an_edge_through_a_triangle_passes_and_one_above_it_does_not() {
        let (x, a, b) = pair(true);
        assert_eq!(through(&b, &a, &x), Some([3, 4, 5]));
        // The flat one's long edge meets the upright's plane at (0.5, 0.5, 0), inside it.
        assert_eq!(through(&a, &b, &x), Some([1, 2, 0]));
        let (x, a, b) = pair(false);
        assert_eq!(through(&b, &a, &x), None);
        assert_eq!(through(&a, &b, &x), None);
    }

    #[test]
    fn neighbours_in_one_plane_do_not_pass_through_each_other() {
        // A quad's two halves and a third triangle beside them, all at z = 0 up to rounding.
        let x: Vec<Vec3> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (2.0, 0.5)]
            .iter()
            .map(|&(u, v)| Vec3::new(u, v, 1e-17 * (u - v)))
            .collect();
        assert_eq!(through(&[0, 1, 3], &[2, 4, 1], &x), None);
        assert_eq!(through(&[2, 4, 1], &[0, 1, 3], &x), None);
    }
}
