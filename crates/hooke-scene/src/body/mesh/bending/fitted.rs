//! Bending on a mesh of any triangulation: `½ B Σ_v A_v (|x_uu|² + 2|x_uw|² + |x_ww|²)`,
//! the second derivatives of the position fitted to each vertex's neighbourhood at rest
//! rather than read off its triangles' angles, written as zero-rest-length springs
//! (docs/physics.md §1.1, "Bending on slivers"), on meshes with slivers.
//!
//! For a bend that keeps lengths, `x_ab` is the second fundamental form times the normal,
//! so the sum is `κ₁² + κ₂²`: the plate's energy at Poisson's ratio 0, and for a roll the
//! `½ B κ²` of Bergou et al. 2006's quadratic model. Their hinges weigh each edge by its
//! triangles' heights, so a sliver's hinge (a height of a hair under a long edge) is
//! stiffer than any curvature its neighbourhood can hold by the edge over the height,
//! squared. Here each vertex `v` takes the weights `c_j` on chosen neighbours that give
//! every quadratic of the rest tangent plane its exact second derivatives, the smallest
//! such weights (a generalised finite difference); the neighbours are chosen so that none
//! is a hair away and the weights scale as one over the neighbourhood's radius squared
//! (see [`second_derivatives`]). Each row `Σ_k C_k x_k` (the centre's weight `−Σ c_j`) has
//! `Σ_k C_k = 0`, so `|Σ C x|² = −Σ_{k<l} C_k C_l |x_k − x_l|²`: zero-rest springs of
//! stiffness `−B A_v C_k C_l`, summed per pair.

use crate::body::mesh::bending::PairSprings;
use crate::body::mesh::sheet::vertex_shares;
use hooke_core::Vec3;
use nalgebra::{Matrix5, Vector5};
use rayon::prelude::*;
use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap, HashMap};

/// A vertex's neighbours, ascending, each with its weights for `x_uu`, `x_uw` and `x_ww`.
type Stencil = Vec<(u32, [f64; 3])>;

/// The sectors of a vertex's tangent plane that its neighbours are chosen from.
const SECTORS: usize = 8;

/// The most vertices each sector gives a vertex's neighbourhood.
const ROUNDS: usize = 3;

/// The largest weight a fit may give a neighbour, times the neighbourhood's radius squared:
/// the three-point difference's is 1, and a fit that needs more leans on neighbours nearly
/// in line, whose weights would grow without bound.
const HEAVIEST: f64 = 8.0;

/// The most vertices a search for a vertex's neighbours reaches.
const MOST_REACHED: usize = 4096;

/// The smallest ratio of the fitting matrix's least to greatest eigenvalue that counts as
/// spanning the quadratics: below it the weights would grow without bound.
const SPANS: f64 = 1e-4;

/// The zero-rest-length springs of the bending energy of `polygons` (corner indices into
/// `x`, the rest shape) for a rigidity `bending` (N·m), summed per pair of particles, in
/// ascending order of the pair. A vertex with no fit (a strip one face wide) adds none.
pub(crate) fn fitted_springs(x: &[Vec3], polygons: &[Vec<u32>], bending: f64) -> PairSprings {
    let n = x.len();
    let area = vertex_shares(x, polygons, 1.0);
    let mut ring: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut normal = vec![Vec3::zeros(); n];
    for p in polygons {
        // Newell's normal, wound as the face is (twice its area along it).
        let mut newell = Vec3::zeros();
        for k in 0..p.len() {
            newell += x[p[k] as usize].cross(&x[p[(k + 1) % p.len()] as usize]);
        }
        for &v in p {
            normal[v as usize] += newell;
            ring[v as usize].extend(p.iter().filter(|&&w| w != v));
        }
    }
    for r in &mut ring {
        r.sort_unstable();
        r.dedup();
    }
    // Each vertex's search is its own, so they run in parallel; the sums below run in
    // vertex order, the same bits on any number of threads.
    let stencils: Vec<Option<Stencil>> = (0..n)
        .into_par_iter()
        .map(|v| second_derivatives(v, x, &ring, normal[v]))
        .collect();
    let mut out: BTreeMap<(u32, u32), f64> = BTreeMap::new();
    for (v, stencil) in stencils.into_iter().enumerate() {
        let Some(stencil) = stencil else {
            continue;
        };
        // `x_uu`, `x_uw` (counted twice: the Hessian's two off-diagonal entries) and `x_ww`.
        for (row, times) in [(0, 1.0), (1, 2.0), (2, 1.0)] {
            let centre = -stencil.iter().map(|(_, c)| c[row]).sum::<f64>();
            let terms: Vec<(u32, f64)> = std::iter::once((v as u32, centre))
                .chain(stencil.iter().map(|(w, c)| (*w, c[row])))
                .collect();
            let scale = bending * area[v] * times;
            for (m, &(k, ck)) in terms.iter().enumerate() {
                for &(l, cl) in &terms[m + 1..] {
                    *out.entry((k.min(l), k.max(l))).or_insert(0.0) -= scale * ck * cl;
                }
            }
        }
    }
    out.into_iter().filter(|(_, k)| *k != 0.0).collect()
}

/// Vertex `v`'s weights on its neighbours (ascending) for `∂²/∂u²`, `∂²/∂u∂w` and
/// `∂²/∂w²` along two directions across `normal`.
///
/// The neighbours are chosen by the octant rule of generalised finite differences (Benito,
/// Ureña and Gavete 2001), made blind to slivers: the vertices reached through the mesh
/// (`ring`, the vertices sharing a face) are sorted into eight sectors of the tangent plane
/// around `v`; the radius `ρ` is the farthest of the sectors' nearest, so that the
/// neighbourhood reaches round `v`; each sector gives its nearest vertex at least `ρ/2`
/// away, and, if those do not span the quadratics (a boundary, where half the sectors are
/// empty), its next at least half as far again. A vertex a hair away (a sliver's short
/// edge) is never taken, and the weights scale as `1/ρ²`.
fn second_derivatives(v: usize, x: &[Vec3], ring: &[Vec<u32>], normal: Vec3) -> Option<Stencil> {
    let normal = normal.try_normalize(0.0)?;
    // Any two directions across the normal.
    let seed = if normal.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let t1 = normal.cross(&seed).normalize();
    let t2 = normal.cross(&t1);
    let sector = |w: u32| {
        let d = x[w as usize] - x[v];
        let turn = d.dot(&t2).atan2(d.dot(&t1)) / std::f64::consts::FRAC_PI_4 + 0.5;
        turn.floor().rem_euclid(SECTORS as f64) as usize
    };
    let distance = |w: u32| (x[w as usize] - x[v]).norm();
    // Dijkstra over the rest mesh (a distance's bits order as the distance does), until
    // every sector has a vertex or the search has gone thrice as far as `v`'s farthest
    // neighbour (past a boundary, sectors stay empty; a sliver's long edge sets how far
    // its corner must look).
    let reach = 3.0 * ring[v].iter().map(|&w| distance(w)).fold(0.0, f64::max);
    let mut best: HashMap<u32, f64> = HashMap::from([(v as u32, 0.0)]);
    let mut queue = BinaryHeap::from([Reverse((0u64, v as u32))]);
    // Each vertex reached with its sector and distance, worked out once.
    let mut reached: Vec<(u32, usize, f64)> = Vec::new();
    let mut nearest = [f64::INFINITY; SECTORS];
    let mut filled_at = 0.0f64;
    while let Some(Reverse((bits, w))) = queue.pop() {
        let along = f64::from_bits(bits);
        if best.get(&w).is_some_and(|&b| b < along) {
            continue;
        }
        if nearest.iter().all(|d| d.is_finite()) && along > filled_at
            || along > reach
            || reached.len() >= MOST_REACHED
        {
            break;
        }
        for &u in &ring[w as usize] {
            let through = along + (x[u as usize] - x[w as usize]).norm();
            if best.get(&u).is_none_or(|&b| through < b) {
                best.insert(u, through);
                queue.push(Reverse((through.to_bits(), u)));
            }
        }
        if w as usize == v {
            continue;
        }
        let (s, d) = (sector(w), distance(w));
        if d == 0.0 {
            continue;
        }
        if !nearest[s].is_finite() {
            filled_at = along;
        }
        nearest[s] = nearest[s].min(d);
        reached.push((w, s, d));
    }
    let rho = nearest
        .iter()
        .filter(|d| d.is_finite())
        .fold(0.0f64, |a, &d| a.max(d));
    reached.sort_unstable_by_key(|r| r.0);
    // The sector's nearest vertex at least `from` away, as `(distance, index)`.
    let pick = |s: usize, from: f64| {
        reached
            .iter()
            .filter(|r| r.1 == s && r.2 >= from)
            .map(|r| (r.2, r.0))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
    };
    let mut stencil: Vec<u32> = Vec::new();
    let mut lasts = [0.0; SECTORS];
    for (s, last) in lasts.iter_mut().enumerate() {
        if let Some((d, w)) = pick(s, 0.5 * rho) {
            stencil.push(w);
            *last = d;
        }
    }
    // Past a boundary, or where a sector's nearest lie on a line, take each sector's next
    // at least half as far again.
    for round in 1..=ROUNDS {
        if let Some(weights) = fit(v, x, &stencil, t1, t2) {
            return Some(weights);
        }
        if round == ROUNDS {
            break;
        }
        for (s, last) in lasts.iter_mut().enumerate() {
            if let Some((d, w)) = pick(s, 1.5 * *last).filter(|_| *last > 0.0) {
                stencil.push(w);
                *last = d;
            }
        }
    }
    None
}

/// The weights of `stencil` for the three second derivatives at `v`, if it spans the
/// quadratics of the plane of `t1`, `t2`.
fn fit(v: usize, x: &[Vec3], stencil: &[u32], t1: Vec3, t2: Vec3) -> Option<Stencil> {
    let mut stencil = stencil.to_vec();
    stencil.sort_unstable();
    let plane: Vec<(f64, f64)> = stencil
        .iter()
        .map(|&w| {
            let d = x[w as usize] - x[v];
            (d.dot(&t1), d.dot(&t2))
        })
        .collect();
    let scale = plane.iter().map(|(u, w)| u.hypot(*w)).fold(0.0, f64::max);
    if scale == 0.0 {
        return None;
    }
    let rows: Vec<Vector5<f64>> = plane
        .iter()
        .map(|(u, w)| {
            let (u, w) = (u / scale, w / scale);
            Vector5::new(u, w, u * u, u * w, w * w)
        })
        .collect();
    let gram: Matrix5<f64> = rows.iter().map(|r| r * r.transpose()).sum();
    let eigen = gram.symmetric_eigenvalues();
    let (least, most) = (eigen.min(), eigen.max());
    if most <= 0.0 || least < SPANS * most {
        return None;
    }
    let solve = gram.cholesky()?;
    // Σ c_j q(d_j) = ∂²q for each monomial q: `u²/2`, `uw` and `w²/2` have the
    // second derivatives 1 along their own pair and 0 along the others.
    let ys = [
        Vector5::new(0.0, 0.0, 2.0, 0.0, 0.0),
        Vector5::new(0.0, 0.0, 0.0, 1.0, 0.0),
        Vector5::new(0.0, 0.0, 0.0, 0.0, 2.0),
    ]
    .map(|target| solve.solve(&target));
    let per_area = 1.0 / (scale * scale);
    let heaviest = rows
        .iter()
        .map(|r| ys.iter().map(|y| r.dot(y).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    if heaviest > HEAVIEST {
        return None;
    }
    Some(
        stencil
            .into_iter()
            .zip(rows)
            .map(|(w, r)| (w, ys.map(|y| r.dot(&y) * per_area)))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::mesh::bending::rolls::{energy, rolled_about_z, rolled_errors};

    /// A sheet rolled onto a cylinder of curvature κ either way stores `½ B κ²` per area
    /// within 1 %, regular or jittered (measured: 0.03 %, boundary and all); nothing when
    /// flat.
    #[test]
    fn a_rolled_sheet_stores_half_b_kappa_squared_per_area() {
        for jitter in [0.0, 0.3] {
            let errors = rolled_errors(jitter, &fitted_springs);
            assert!(
                errors.iter().all(|e| e.abs() < 0.01),
                "{jitter}: {errors:?}"
            );
        }
    }

    /// A saddle `y = κ (u² − w²) / 2` stores the plate's `½ B (κ₁² + κ₂²)` per area, not
    /// the nothing that `|Δx|²` would give it; the flat sheet stores nothing.
    #[test]
    fn a_saddle_stores_half_b_times_both_curvatures_squared() {
        let (n, h, b, kappa) = (30, 0.01, 5e-6, 0.5);
        let id = |i: usize, j: usize| (i * n + j) as u32;
        let flat: Vec<Vec3> = (0..n * n)
            .map(|k| Vec3::new((k / n) as f64 * h, 0.0, (k % n) as f64 * h))
            .collect();
        let mut polygons = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                polygons.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let springs = fitted_springs(&flat, &polygons, b);
        let c = (n - 1) as f64 * h / 2.0;
        let saddle: Vec<Vec3> = flat
            .iter()
            .map(|p| {
                let (u, w) = (p.x - c, p.z - c);
                Vec3::new(p.x, 0.5 * kappa * (u * u - w * w), p.z)
            })
            .collect();
        let area = (2.0 * c).powi(2);
        let want = 0.5 * b * 2.0 * kappa * kappa * area;
        let got = energy(&springs, &saddle);
        assert!((got / want - 1.0).abs() < 0.02, "{got} vs {want}");
        assert!(energy(&springs, &flat).abs() < 1e-9 * want);
    }

    /// A disc as Blender fills a circle: one fan of needles from a point on its rim,
    /// subdivided twice (each triangle into four), edges from 1.8 mm to a quarter of the
    /// diameter. Rolled, it stores `½ B κ²` per area within 5 %. Its stiffest bending spring
    /// over the lighter end's area (`ks/m` but for the density) is under 100 `B/h⁴`, with
    /// `h` the shortest edge: a regular grid of that spacing has 4.3 (quads) and 4.8
    /// (triangles). (Measured: 43; the hinges gave 1.7·10⁷, a hinge over a needle's long
    /// edge being stiffer by the edge over the needle's height, squared.)
    #[test]
    fn a_fan_of_needles_bends_as_the_fabric_with_bounded_springs() {
        let (r, b, kappa) = (0.15, 5e-6, 2.0);
        let (disc, polygons) = crate::example_meshes::fan_disc(r, 128, 2);
        let disc: Vec<Vec3> = disc.iter().map(|p| Vec3::from(*p)).collect();
        let springs = fitted_springs(&disc, &polygons, b);
        let shortest = polygons
            .iter()
            .flat_map(|t| {
                (0..3).map(|k| (disc[t[k] as usize] - disc[t[(k + 1) % 3] as usize]).norm())
            })
            .fold(f64::INFINITY, f64::min);
        let area = vertex_shares(&disc, &polygons, 1.0);
        let stiffest = springs
            .iter()
            .map(|((i, j), k)| k.abs() / area[*i as usize].min(area[*j as usize]))
            .fold(0.0, f64::max);
        assert!(
            stiffest < 100.0 * b / shortest.powi(4),
            "{stiffest:e} against B/h⁴ {:e}",
            b / shortest.powi(4)
        );
        let want = 0.5 * b * kappa * kappa * std::f64::consts::PI * r * r;
        let got = energy(&springs, &rolled_about_z(&disc, kappa));
        assert!((got / want - 1.0).abs() < 0.05, "{got} vs {want}");
    }
}
