//! Surfaces that start nearer each other than their contacts keep them: two bodies, or two
//! pieces of one body that no face joins (a sheet written twice, a garment's layers saved
//! as separate pieces). The contacts push them apart in the first steps, which is seldom
//! what the author meant, so a scene that does is warned about (docs/physics.md §3.4).

use crate::joined::Joined;
use crate::scene::Scene;
use hooke_core::{Num, Spring, Vec3};
use std::collections::{HashMap, HashSet};

/// Pairs of bodies that start through each other, or nearer than the sum of their contact
/// thicknesses: a spring of one passing that near a triangle of the other.
pub(crate) fn overlapping_bodies(scene: &Scene) -> Vec<String> {
    let x = &scene.simulation.particles().x;
    let springs = &scene.simulation.model().springs;
    let mut said = Vec::new();
    for (a, body) in scene.bodies.iter().enumerate() {
        for (b, other) in scene.bodies.iter().enumerate() {
            if a == b || other.triangles.is_empty() || (a > b && !body.triangles.is_empty()) {
                // Each pair once, but a body without triangles only from its side.
                continue;
            }
            let reach = body.thickness + other.thickness;
            let everywhere = |_: &Spring, _: &[u32; 3]| true;
            let mut near = hits(
                x,
                &within(springs, &body.range),
                &other.triangles,
                reach,
                everywhere,
            );
            if !body.triangles.is_empty() {
                let mine = within(springs, &other.range);
                near += hits(x, &mine, &body.triangles, reach, everywhere);
            }
            if near > 0 {
                said.push(format!(
                    "bodies '{}' and '{}' start through each other or nearer than their \
                     contact thicknesses ({} m together): {near} of their springs pass \
                     that near the other's surface, and the contacts will tear them apart \
                     in the first steps; start them further apart (their `origin`)",
                    body.name,
                    other.name,
                    Num(reach)
                ));
            }
        }
    }
    said
}

/// Bodies with pieces that no face joins starting through each other or nearer than the
/// body's contact thickness (what its self-contact keeps), as a sheet and its copy would.
pub(crate) fn overlapping_pieces(scene: &Scene) -> Vec<String> {
    let x = &scene.simulation.particles().x;
    let springs = &scene.simulation.model().springs;
    let mut said = Vec::new();
    for body in &scene.bodies {
        let self_contact = scene
            .simulation
            .model()
            .surfaces
            .iter()
            .any(|s| s.particles == body.range && s.self_collision);
        if body.triangles.is_empty() || body.thickness <= 0.0 || !self_contact {
            continue;
        }
        let piece = pieces(&body.triangles, &body.range);
        if piece.iter().max().is_none_or(|&m| m == 0) {
            continue;
        }
        let of = |i: u32| piece[i as usize - body.range.start];
        let mine = within(springs, &body.range);
        let apart = |s: &Spring, t: &[u32; 3]| of(s.i) != of(t[0]) && of(s.j) != of(t[0]);
        let near = hits(x, &mine, &body.triangles, body.thickness, apart);
        if near > 0 {
            said.push(format!(
                "body '{}': pieces of it that no face joins start through each other or \
                 nearer than its contact thickness ({} m): {near} of its springs pass that \
                 near another piece's surface, and its self-contact will push them apart in \
                 the first steps; move the pieces apart, remove a duplicate, or join them \
                 (`shape.weld` welds vertices within a distance)",
                body.name,
                Num(body.thickness)
            ));
        }
    }
    said
}

/// The springs with both ends in `range` (one body's).
fn within<'a>(springs: &'a [Spring], range: &std::ops::Range<usize>) -> Vec<&'a Spring> {
    springs
        .iter()
        .filter(|s| range.contains(&(s.i as usize)) && range.contains(&(s.j as usize)))
        .collect()
}

/// Each particle of `range` numbered by the piece of `triangles` it belongs to (pieces
/// joined through shared corners, numbered from 0 in order of their first particle); a
/// particle in no triangle is its own piece.
fn pieces(triangles: &[[u32; 3]], range: &std::ops::Range<usize>) -> Vec<usize> {
    let mut joined = Joined::new(range.len());
    for t in triangles {
        let [a, b, c] = t.map(|i| (i as usize - range.start) as u32);
        joined.join(a, b);
        joined.join(b, c);
    }
    let mut number = HashMap::new();
    (0..range.len() as u32)
        .map(|i| {
            let next = number.len();
            *number.entry(joined.root(i)).or_insert(next)
        })
        .collect()
}

/// How many of the springs `mine` pass within `reach` (or through) a triangle of
/// `triangles` that `counts` admits for them, found through a uniform grid of the
/// triangles' boxes.
fn hits(
    x: &[Vec3],
    mine: &[&Spring],
    triangles: &[[u32; 3]],
    reach: f64,
    counts: impl Fn(&Spring, &[u32; 3]) -> bool,
) -> usize {
    use hooke_core::contact::proximity::segment_triangle;
    let corners = |t: &[u32; 3]| t.map(|i| x[i as usize]);
    let bounds = |points: &[Vec3]| {
        let inf = Vec3::repeat(f64::INFINITY);
        points
            .iter()
            .fold((inf, -inf), |(lo, hi), p| (lo.inf(p), hi.sup(p)))
    };
    if mine.is_empty() || triangles.is_empty() {
        return 0;
    }
    let (lo_a, hi_a) = bounds(
        &mine
            .iter()
            .flat_map(|s| [x[s.i as usize], x[s.j as usize]])
            .collect::<Vec<_>>(),
    );
    let (lo_b, hi_b) = bounds(&triangles.iter().flat_map(corners).collect::<Vec<_>>());
    if (0..3).any(|k| lo_a[k] > hi_b[k] + reach || lo_b[k] > hi_a[k] + reach) {
        return 0;
    }
    // Cells about a triangle's size: each spring meets a few.
    let longest = triangles
        .iter()
        .map(|t| {
            let [p, q, r] = corners(t);
            (p - q).norm().max((q - r).norm()).max((r - p).norm())
        })
        .fold(0.0f64, f64::max);
    let cell = longest.max(reach).max(1e-6);
    let key = |p: &Vec3| p.map(|c| (c / cell).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (k, t) in triangles.iter().enumerate() {
        let (lo, hi) = bounds(&corners(t));
        let (lo, hi) = (key(&lo.add_scalar(-reach)), key(&hi.add_scalar(reach)));
        for i in lo.x..=hi.x {
            for j in lo.y..=hi.y {
                for l in lo.z..=hi.z {
                    grid.entry([i, j, l]).or_default().push(k);
                }
            }
        }
    }
    let reach2 = reach.max(1e-9).powi(2);
    mine.iter()
        .filter(|s| {
            let (p, q) = (x[s.i as usize], x[s.j as usize]);
            let (lo, hi) = bounds(&[p, q]);
            let (lo, hi) = (key(&lo), key(&hi));
            let mut seen = HashSet::new();
            for i in lo.x..=hi.x {
                for j in lo.y..=hi.y {
                    for l in lo.z..=hi.z {
                        for &k in grid.get(&[i, j, l]).into_iter().flatten() {
                            if !seen.insert(k) || !counts(s, &triangles[k]) {
                                continue;
                            }
                            let [a, b, c] = corners(&triangles[k]);
                            let (t, w) = segment_triangle(&p, &q, &a, &b, &c);
                            let on_segment = p + (q - p) * t;
                            let on_triangle = a * w[0] + b * w[1] + c * w[2];
                            if (on_segment - on_triangle).norm_squared() < reach2 {
                                return true;
                            }
                        }
                    }
                }
            }
            false
        })
        .count()
}
