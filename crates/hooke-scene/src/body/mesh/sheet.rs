//! A cloth's mesh as read from the user's OBJ: vertices welded by the file's position index
//! (or by distance, for a triangle soup), faces cleaned, edges checked, and the map from the
//! file's vertices to the particles that the outputs use to hand them back in order.

use crate::error::{BuildError, invalid};
use crate::joined::Joined;
use crate::skin::{Skin, SkinVertex};
use hooke_collide::PolygonMesh;
use hooke_core::{Num, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// A cloth's mesh, ready for springs.
pub(crate) struct Sheet {
    /// Particle positions in the body's frame (the file's coordinates, scaled).
    pub(crate) local: Vec<Vec3>,
    /// The file's coordinates of each particle (for pin regions, which are given in them).
    pub(crate) file: Vec<Vec3>,
    /// Each file vertex's particle, if a kept face uses it.
    pub(crate) particle_of: Vec<Option<u32>>,
    /// The kept faces as particle indices (at least 3 distinct corners, nonzero area).
    pub(crate) polygons: Vec<Vec<u32>>,
    /// The group indices of each kept face.
    pub(crate) polygon_groups: Vec<Vec<u32>>,
    /// The file's group names.
    pub(crate) groups: Vec<String>,
    /// The kept faces cut into triangles: quads along their shorter diagonal, other
    /// polygons as fans from their first corner.
    pub(crate) triangles: Vec<[u32; 3]>,
    /// The user's mesh, with particle indices relative to the body.
    pub(crate) skin: Skin,
    /// What was done to the mesh that the user should hear of.
    pub(crate) warnings: Vec<String>,
}

/// Reads a cloth mesh: `mesh` from `path` (named in messages), its coordinates multiplied by
/// `scale`, vertices within `weld` of each other (in the file's coordinates) merged.
pub(crate) fn sheet(
    mesh: PolygonMesh,
    path: &Path,
    key: &str,
    scale: Vec3,
    weld: Option<f64>,
) -> Result<Sheet, BuildError> {
    let shown = path.display();
    let n = mesh.positions.len();
    let welded = match weld {
        Some(d) => weld_by_distance(&mesh.positions, d),
        None => (0..n as u32).collect(),
    };
    // Faces in welded vertex indices, with repeated corners removed; those left with fewer
    // than three corners, or no area, are dropped.
    let extent = bounds_diagonal(&mesh.positions);
    let mut kept: Vec<(Vec<u32>, usize, Vec<u32>)> = Vec::new();
    let mut dropped: Vec<usize> = Vec::new();
    for face in &mesh.faces {
        let mut corners: Vec<u32> = Vec::with_capacity(face.corners.len());
        for &c in &face.corners {
            let w = welded[c as usize];
            if corners.last() != Some(&w) {
                corners.push(w);
            }
        }
        while corners.len() > 1 && corners.first() == corners.last() {
            corners.pop();
        }
        let distinct = {
            let mut s = corners.clone();
            s.sort_unstable();
            s.dedup();
            s.len()
        };
        let area = polygon_area(&corners, &mesh.positions);
        if distinct < 3 || distinct != corners.len() || area <= 1e-12 * extent * extent {
            dropped.push(face.line);
            continue;
        }
        kept.push((corners, face.line, face.groups.clone()));
    }
    if let (true, Some(d)) = (kept.is_empty(), weld) {
        let edges = mesh.faces.iter().flat_map(|f| {
            let c = &f.corners;
            (0..c.len()).map(move |k| (c[k], c[(k + 1) % c.len()]))
        });
        let shortest = edges
            .map(|(a, b)| (mesh.positions[a as usize] - mesh.positions[b as usize]).norm())
            .filter(|&l| l > 0.0)
            .fold(f64::INFINITY, f64::min);
        if shortest <= d {
            return Err(invalid(
                format!("{key}.shape.weld"),
                format!(
                    "{shown}: weld = {} m merges the corners of every face (the file's \
                     shortest edge is {} m): make weld smaller than that",
                    Num(d),
                    Num(shortest)
                ),
            ));
        }
    }
    if kept.is_empty() {
        return Err(invalid(
            format!("{key}.shape.path"),
            format!("{shown}: every face has zero area; a cloth needs at least one triangle"),
        ));
    }
    // An edge of three faces is no surface a cloth can be.
    let mut edges: HashMap<(u32, u32), (u32, usize)> = HashMap::new();
    for (corners, line, _) in &kept {
        for k in 0..corners.len() {
            let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
            let e = edges.entry((a.min(b), a.max(b))).or_insert((0, *line));
            e.0 += 1;
            if e.0 == 3 {
                return Err(invalid(
                    format!("{key}.shape.path"),
                    format!(
                        "{shown}:{line}: the edge between vertices {} and {} is shared by a \
                         third face (the first is on line {}); a cloth's edge joins at most two",
                        a + 1,
                        b + 1,
                        e.1
                    ),
                ));
            }
        }
    }
    // Particles: the used (welded) vertices, in the file's order.
    let mut used = vec![false; n];
    for (corners, ..) in &kept {
        for &c in corners {
            used[c as usize] = true;
        }
    }
    let mut particle_of_welded = vec![None; n];
    let mut local = Vec::new();
    let mut file = Vec::new();
    for v in 0..n {
        if used[v] {
            particle_of_welded[v] = Some(local.len() as u32);
            local.push(mesh.positions[v].component_mul(&scale));
            file.push(mesh.positions[v]);
        }
    }
    let particle_of: Vec<Option<u32>> = (0..n)
        .map(|v| particle_of_welded[welded[v] as usize])
        .collect();
    let unreferenced: Vec<usize> = (0..n).filter(|&v| particle_of[v].is_none()).collect();
    let mut warnings = Vec::new();
    if !dropped.is_empty() {
        warnings.push(format!(
            "{shown}: {} face{} with no area (a repeated corner or all corners in a line) \
             dropped, the first on line {}",
            dropped.len(),
            if dropped.len() == 1 { "" } else { "s" },
            dropped[0]
        ));
    }
    if !unreferenced.is_empty() {
        warnings.push(format!(
            "{shown}: {} {} in no face (the first on line {}) simulate nothing; the \
             exports keep {} where the body placed {}",
            unreferenced.len(),
            if unreferenced.len() == 1 {
                "vertex"
            } else {
                "vertices"
            },
            mesh.position_lines[unreferenced[0]],
            if unreferenced.len() == 1 {
                "it"
            } else {
                "them"
            },
            if unreferenced.len() == 1 {
                "it"
            } else {
                "them"
            },
        ));
    }
    if let Some(d) = weld {
        let merged = n - unreferenced.len() - local.len();
        if merged > 0 {
            warnings.push(format!(
                "{shown}: weld = {} m merged {merged} vertices into others",
                Num(d)
            ));
        }
    }
    let polygons: Vec<Vec<u32>> = kept
        .iter()
        .map(|(c, ..)| {
            c.iter()
                .map(|&v| particle_of_welded[v as usize].expect("a used vertex"))
                .collect()
        })
        .collect();
    let triangles = polygons.iter().flat_map(|p| split(p, &local)).collect();
    let vertices = (0..n)
        .map(|v| match particle_of[v] {
            Some(p) => SkinVertex::Particle(p),
            None => SkinVertex::Fixed(mesh.positions[v].component_mul(&scale)),
        })
        .collect();
    let skin = Skin::of_file(&mesh, vertices);
    Ok(Sheet {
        local,
        file,
        particle_of,
        polygons,
        polygon_groups: kept.into_iter().map(|(.., g)| g).collect(),
        groups: mesh.groups,
        triangles,
        skin,
        warnings,
    })
}

/// A polygon of four or more corners read from its lowest-numbered corner toward the lower
/// of that corner's two neighbours: the same list whichever corner a file starts a face on
/// and whichever way it winds, so that what is computed from a face (its cut, its fan, its
/// area, its membrane) is the same bits for the same fabric. A triangle, which has only
/// one cut, is kept as written (so the built-in meshes keep their bits).
pub(crate) fn canonical(p: &[u32]) -> Vec<u32> {
    let n = p.len();
    let Some(first) = (0..n).min_by_key(|&k| p[k]).filter(|_| n > 3) else {
        return p.to_vec();
    };
    let (next, prev) = (p[(first + 1) % n], p[(first + n - 1) % n]);
    if next <= prev {
        (0..n).map(|k| p[(first + k) % n]).collect()
    } else {
        (0..n).map(|k| p[(first + n - k) % n]).collect()
    }
}

/// Whether `canonical(p)` winds as `p` does.
fn winds_as_given(p: &[u32], c: &[u32]) -> bool {
    let n = p.len();
    let first = p.iter().position(|&v| v == c[0]).unwrap_or(0);
    n < 3 || p[(first + 1) % n] == c[1]
}

/// A polygon's triangles, wound as the polygon is: a quad along its shorter diagonal (so a
/// skinny quad is not cut into two slivers; of two equal ones, the one through the
/// lowest-numbered corner), anything else as a fan from its lowest-numbered corner. The
/// cut does not depend on the corner a face starts on or on its winding.
pub(crate) fn split(p: &[u32], x: &[Vec3]) -> Vec<[u32; 3]> {
    let c = canonical(p);
    let mut out: Vec<[u32; 3]> = if c.len() == 4 {
        let d02 = (x[c[0] as usize] - x[c[2] as usize]).norm_squared();
        let d13 = (x[c[1] as usize] - x[c[3] as usize]).norm_squared();
        if d13 < d02 {
            vec![[c[0], c[1], c[3]], [c[1], c[2], c[3]]]
        } else {
            vec![[c[0], c[1], c[2]], [c[0], c[2], c[3]]]
        }
    } else {
        (1..c.len().saturating_sub(1))
            .map(|k| [c[0], c[k], c[k + 1]])
            .collect()
    };
    if !winds_as_given(p, &c) {
        for t in &mut out {
            t.swap(1, 2);
        }
    }
    out
}

/// The area of a polygon (Newell's method: exact for planar ones), summed in the canonical
/// order so that it is the same bits however the face is written.
pub(crate) fn polygon_area(p: &[u32], x: &[Vec3]) -> f64 {
    let p = &canonical(p)[..];
    let mut n = Vec3::zeros();
    for k in 0..p.len() {
        let (a, b) = (x[p[k] as usize], x[p[(k + 1) % p.len()] as usize]);
        n += a.cross(&b);
    }
    0.5 * n.norm()
}

/// Each vertex's equal share of the area of every polygon it is a corner of, times
/// `per_area` (a density gives the masses; 1 the areas themselves).
pub(crate) fn vertex_shares(x: &[Vec3], polygons: &[Vec<u32>], per_area: f64) -> Vec<f64> {
    let mut out = vec![0.0; x.len()];
    for p in polygons {
        let share = per_area * polygon_area(p, x) / p.len() as f64;
        for &v in p {
            out[v as usize] += share;
        }
    }
    out
}

/// The diagonal of the points' bounding box.
pub(crate) fn bounds_diagonal(x: &[Vec3]) -> f64 {
    let (lo, hi) = x.iter().fold(
        (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    if x.is_empty() { 0.0 } else { (hi - lo).norm() }
}

/// Each vertex's representative: the lowest-numbered vertex within `d` of it, through any
/// chain of such neighbours (found on a grid of cells `d` wide).
fn weld_by_distance(x: &[Vec3], d: f64) -> Vec<u32> {
    let mut welded = Joined::new(x.len());
    let cell = |p: &Vec3| (p / d).map(|c| c.floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (i, p) in x.iter().enumerate() {
        let c = cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(near) = grid.get(&[c.x + dx, c.y + dy, c.z + dz]) else {
                        continue;
                    };
                    for &j in near {
                        if (x[j as usize] - p).norm() <= d {
                            welded.join(i as u32, j);
                        }
                    }
                }
            }
        }
        grid.entry([c.x, c.y, c.z]).or_default().push(i as u32);
    }
    (0..x.len() as u32).map(|i| welded.root(i)).collect()
}
