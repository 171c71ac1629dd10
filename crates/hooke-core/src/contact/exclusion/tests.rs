//! The exclusion's lists against every pair within the reach, measured one by one.

use super::*;
use crate::model::Model;
use crate::model::surface::Surface;

/// A fixed pseudo-random sequence in `[-0.5, 0.5)`.
fn noise(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// An `n`×`n` sheet of spacing `s` in the x-z plane, its quads split along a diagonal
/// that `flip` chooses, its points placed by `at(i, j)`; thickness `h`.
pub(crate) fn sheet(
    n: usize,
    h: f64,
    mut flip: impl FnMut(usize, usize) -> bool,
    mut at: impl FnMut(usize, usize) -> Vec3,
) -> (Model, Vec<Vec3>) {
    let mut x = Vec::new();
    for j in 0..n {
        for i in 0..n {
            x.push(at(i, j));
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as u32;
            let (b, c, d) = (a + 1, a + n as u32, a + n as u32 + 1);
            if flip(i, j) {
                triangles.extend([[a, b, c], [b, d, c]]);
            } else {
                triangles.extend([[a, b, d], [a, d, c]]);
            }
        }
    }
    let model = Model {
        surfaces: vec![Surface {
            particles: 0..n * n,
            triangles,
            thickness: h,
            self_collision: true,
            friction: 0.0,
        }],
        ..Model::default()
    };
    (model, x)
}

/// A model's surfaces as the detection indexes them: every active surface's triangles,
/// then its edges, each with its surface.
struct Prims {
    triangles: Vec<[u32; 3]>,
    edges: Vec<[u32; 2]>,
    surface: Vec<Option<usize>>,
}

impl Prims {
    fn of(model: &Model, n: usize) -> Self {
        let mut prims = Prims {
            triangles: Vec::new(),
            edges: Vec::new(),
            surface: vec![None; n],
        };
        for (k, s) in model.surfaces.iter().enumerate() {
            s.particles.clone().for_each(|p| prims.surface[p] = Some(k));
            prims.triangles.extend(&s.triangles);
            prims.edges.extend(s.edges());
        }
        prims
    }

    fn exclusion(&self, x: &[Vec3], radius: f64) -> Exclusion {
        let on = |v: u32| self.surface[v as usize].is_some();
        let surfaces = Surfaces {
            triangles: &self.triangles,
            edges: &self.edges,
            self_colliding: &on,
            self_pairs: true,
        };
        Exclusion::new(&surfaces, x, (radius, radius), &|_| false)
    }

    /// Every particle–triangle pair of one surface within `reach` at `x` (the particle not
    /// a corner), and every edge–edge pair sharing no particle, once.
    fn within(&self, x: &[Vec3], reach: f64) -> (Vec<[u32; 2]>, Vec<[u32; 2]>) {
        let at = |i: u32| &x[i as usize];
        let mut points = Vec::new();
        for v in 0..x.len() as u32 {
            for (t, tri) in self.triangles.iter().enumerate() {
                if self.surface[v as usize] == self.surface[tri[0] as usize]
                    && !tri.contains(&v)
                    && point_triangle_distance(at(v), tri.map(at)) <= reach
                {
                    points.push([v, t as u32]);
                }
            }
        }
        let mut edges = Vec::new();
        for (e, &[a, b]) in self.edges.iter().enumerate() {
            for (f, &[c, d]) in self.edges.iter().enumerate().skip(e + 1) {
                if self.surface[a as usize] == self.surface[c as usize]
                    && ![c, d].contains(&a)
                    && ![c, d].contains(&b)
                    && segment_distance([a, b, c, d].map(at)) <= reach
                {
                    edges.push([e as u32, f as u32]);
                }
            }
        }
        (points, edges)
    }
}

/// The pairs within `reach` at `x`, with and without the exclusion built at `x` for that
/// reach.
fn pairs(model: &Model, x: &[Vec3], reach: f64) -> (usize, usize, Exclusion) {
    let prims = Prims::of(model, x.len());
    let skip = prims.exclusion(x, reach);
    let (points, edges) = prims.within(x, reach);
    let left = points
        .iter()
        .filter(|[v, t]| !skip.skips_triangle(*v, *t))
        .count()
        + edges
            .iter()
            .filter(|[e, f]| !skip.skips_edges(*e, *f))
            .count();
    (points.len() + edges.len(), left, skip)
}

/// On a flat sheet at rest the exclusion leaves no pair within the reach of a grid at
/// the 128² drape's reach (just over a spacing), and at most a fifth of them where paths
/// along the edges are longer than the straight distance: a grid whose reach spans three
/// spacings, its diagonals alternating (2.5 % measured), and one with its diagonals
/// mixed and its points jittered by up to 0.3 spacings (13 %).
#[test]
fn a_flat_sheet_at_rest_leaves_no_pair_of_its_own_to_measure() {
    let s = 0.0126;
    let regular = sheet(
        24,
        s / 4.0,
        |_, _| false,
        |i, j| Vec3::new(i as f64 * s, 0.0, j as f64 * s),
    );
    let mut jitter = noise(7);
    let mut coin = noise(11);
    let irregular = sheet(
        24,
        s / 4.0,
        |_, _| coin() < 0.0,
        |i, j| {
            Vec3::new(
                (i as f64 + 0.6 * jitter()) * s,
                0.0,
                (j as f64 + 0.6 * jitter()) * s,
            )
        },
    );
    let fine = sheet(
        24,
        0.75 * s,
        |i, j| (i + j) % 2 == 0,
        |i, j| Vec3::new(i as f64 * s, 0.0, j as f64 * s),
    );
    for (name, (model, x), reach) in [
        ("regular", regular, 1.016 * s),
        ("irregular", irregular, 1.016 * s),
        ("fine", fine, 3.0 * s),
    ] {
        let (all, left, skip) = pairs(&model, &x, reach);
        assert!(all > 1000, "{name}: {all} pairs without the exclusion");
        let most = if name == "regular" { 0 } else { all / 5 };
        assert!(
            left <= most,
            "{name}: {left} of {all} pairs left ({} skipped)",
            skip.len()
        );
    }
}

/// Connection, not distance: a sheet folded over itself keeps every pair across its
/// layers beyond the exclusion's reach of the fold, and two separate sheets lying on
/// each other skip nothing between them.
#[test]
fn layers_that_are_not_neighbours_along_the_surface_still_collide() {
    let (n, s) = (20usize, 0.01);
    let gap = 0.6 * s;
    let reach = 1.2 * s;
    // The far half turned back over the near half, `gap` above it.
    let (model, x) = sheet(
        n,
        s / 4.0,
        |_, _| false,
        |i, j| {
            if j < n / 2 {
                Vec3::new(i as f64 * s, 0.0, j as f64 * s)
            } else {
                Vec3::new(i as f64 * s, gap, (n - 1 - j) as f64 * s)
            }
        },
    );
    let prims = Prims::of(&model, x.len());
    let skip = prims.exclusion(&x, reach);
    let (points, _) = prims.within(&x, reach);
    // Along the sheet, particle row `j` of the lower layer is `2 (n/2 - 1 - j)` spacings
    // and the fold's height from the upper layer's point above it: beyond the path
    // bound, each must still meet the layer above.
    for j in 0..n / 2 {
        let along = 2.0 * (n / 2 - 1 - j) as f64 * s + gap;
        if along <= PATH * reach + 2.0 * s {
            continue;
        }
        for i in 0..n {
            let v = (j * n + i) as u32;
            let above = points.iter().any(|&[p, t]| {
                p == v
                    && !skip.skips_triangle(p, t)
                    && prims.triangles[t as usize]
                        .iter()
                        .all(|&k| k as usize >= n * n / 2)
            });
            assert!(
                above,
                "particle {v} (row {j}) lost its pair with the layer above"
            );
        }
    }
    // Two sheets, one `gap` above the other: different surfaces, nothing skipped.
    let (mut two, below) = sheet(
        n,
        s / 4.0,
        |_, _| false,
        |i, j| Vec3::new(i as f64 * s, 0.0, j as f64 * s),
    );
    let mut x = below.clone();
    x.extend(below.iter().map(|p| p + Vec3::new(0.0, gap, 0.0)));
    let mut upper = two.surfaces[0].clone();
    let shift = (n * n) as u32;
    upper.particles = n * n..2 * n * n;
    upper
        .triangles
        .iter_mut()
        .flatten()
        .for_each(|k| *k += shift);
    two.surfaces.push(upper);
    let prims = Prims::of(&two, x.len());
    let skip = prims.exclusion(&x, reach);
    for v in 0..(n * n) as u32 {
        for (t, tri) in prims.triangles.iter().enumerate() {
            if prims.surface[tri[0] as usize] == Some(1) {
                assert!(!skip.skips_triangle(v, t as u32), "{v} skips {tri:?}");
            }
        }
    }
}

/// A sliver's corner a hair from the triangle across its long side, both its edges there
/// long against the radius: held apart by the sliver's springs, the pair is skipped (by the
/// neighbour rule, as no corner is near along the edges); a second sheet at that distance
/// is not.
#[test]
fn a_slivers_corner_is_not_a_contact_of_the_triangle_beside_it() {
    // Two triangles on the long side `ab`: the sliver `abv` with `v` 0.1 mm from `ab`'s
    // middle, and `bac` on the other side; a second surface `ghk` 0.1 mm above `v`.
    let x = vec![
        Vec3::new(-0.1, 0.0, 0.0),
        Vec3::new(0.1, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1e-4),
        Vec3::new(0.0, 0.0, -0.1),
        Vec3::new(-0.1, 1e-4, 1e-4),
        Vec3::new(0.1, 1e-4, 1e-4),
        Vec3::new(0.0, 1e-4, 0.1),
    ];
    let surface = |particles, triangles| Surface {
        particles,
        triangles,
        thickness: 0.005,
        self_collision: true,
        friction: 0.0,
    };
    let model = Model {
        surfaces: vec![
            surface(0..4, vec![[0, 1, 2], [1, 0, 3]]),
            surface(4..7, vec![[4, 5, 6]]),
        ],
        ..Model::default()
    };
    let prims = Prims::of(&model, x.len());
    let skip = prims.exclusion(&x, 0.02);
    let (points, _) = prims.within(&x, 0.02);
    assert!(points.contains(&[2, 1]), "the pair is within the radius");
    assert!(
        skip.skips_triangle(2, 1),
        "the sliver's corner meets the triangle beside it"
    );
    for v in 0..4 {
        assert!(!skip.skips_triangle(v, 2), "{v} skips the other sheet");
    }
    for v in 4..7 {
        assert!((0..2).all(|t| !skip.skips_triangle(v, t)));
    }
}

/// The watch on skipped pairs (`folds.rs`): a sheet flat, or rolled a quarter turn, has
/// nothing through itself; the same sheet with one edge at a particle pushed through a
/// triangle it skips (a crease tighter than the skipped pairs) is found.
#[test]
fn an_edge_pushed_through_a_skipped_triangle_is_found_and_a_rolled_sheet_is_not() {
    let (n, s) = (8usize, 0.01);
    let flat = |i: usize, j: usize| Vec3::new(i as f64 * s, 0.0, j as f64 * s);
    let (model, x) = sheet(n, s / 4.0, |_, _| false, flat);
    let prims = Prims::of(&model, x.len());
    let skip = prims.exclusion(&x, 1.016 * s);
    assert!(
        skip.folds().len() > 100,
        "{} pairs watched",
        skip.folds().len()
    );
    assert_eq!(skip.folds().first_through(&x, &mut Vec::new()), None);
    // Rolled about the x axis into a quarter of a cylinder 4 cm in radius.
    let r = 0.04;
    let rolled: Vec<Vec3> = x
        .iter()
        .map(|p| Vec3::new(p.x, r - r * (p.z / r).cos(), r * (p.z / r).sin()))
        .collect();
    assert_eq!(skip.folds().first_through(&rolled, &mut Vec::new()), None);
    // A particle in the middle, a triangle it skips, and an edge at it whose other end
    // and whose triangle share nothing with that triangle.
    let v = (n / 2 * n + n / 2) as u32;
    let tris = &prims.triangles;
    let (t, w) = (0..tris.len() as u32)
        .filter(|&t| skip.skips_triangle(v, t))
        .find_map(|t| {
            let far = |k: &u32| !tris[t as usize].contains(k);
            tris.iter()
                .filter(|a| a.contains(&v) && a.iter().all(far))
                .flat_map(|a| a.iter().copied().filter(|&k| k != v))
                .next()
                .map(|w| (t, w))
        })
        .expect("a skipped triangle beside an edge at the middle particle");
    let centre = tris[t as usize]
        .iter()
        .fold(Vec3::zeros(), |c, &k| c + x[k as usize] / 3.0);
    let mut poked = x.clone();
    poked[v as usize] = centre - Vec3::new(0.0, 0.2 * s, 0.0);
    poked[w as usize] = centre + Vec3::new(0.0, 0.2 * s, 0.0);
    // The edge passes through the triangle, and the flat sheet's edges beside them
    // through the triangles at the two moved particles: some pair is found.
    assert!(
        skip.folds()
            .first_through(&poked, &mut Vec::new())
            .is_some()
    );
}
