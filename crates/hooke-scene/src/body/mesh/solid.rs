//! A jelly from a closed mesh: a lattice filling its inside, carrying its surface.
//!
//! The lattice's cells are those whose centre is inside the mesh (by its winding number)
//! and those holding a vertex. Every vertex then lies in a cell whose eight corners are
//! particles, and rides it trilinearly: its position is a convex combination of the
//! corners', so a convex region that holds the particles (the free side of a plane, the
//! inside of a box) holds the surface too (docs/physics.md §1.1).

use crate::body::mesh::sheet::split;
use crate::error::{BuildError, invalid};
use crate::generators::Lattice;
use crate::skin::{Skin, SkinVertex};
use hooke_collide::PolygonMesh;
use hooke_core::{SpringKind, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// A filled mesh: the lattice's particles and springs (local indices), and the surface.
pub(crate) struct Filled {
    /// Particle positions in the body's frame.
    pub(crate) local: Vec<Vec3>,
    /// Springs of each family present: `(i, j, rest)` in local indices.
    pub(crate) springs: Vec<(SpringKind, u32, u32, f64)>,
    /// The lattice's outer faces as triangles (local indices): its contact surface.
    pub(crate) boundary: Vec<[u32; 3]>,
    /// The user's mesh riding the lattice (local particle indices).
    pub(crate) skin: Skin,
    /// What the user should know about the mesh (it is filled all the same).
    pub(crate) warnings: Vec<String>,
}

/// Fills `mesh` (from `path`, its coordinates times `scale`) with a lattice of `spacing`,
/// refusing an open mesh (its open edges counted) and one smaller than a cell.
pub(crate) fn fill(
    mesh: &PolygonMesh,
    path: &Path,
    key: &str,
    scale: Vec3,
    spacing: f64,
    limit: usize,
) -> Result<Filled, BuildError> {
    let shown = path.display();
    let x: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|p| p.component_mul(&scale))
        .collect();
    let triangles: Vec<[u32; 3]> = mesh
        .faces
        .iter()
        .flat_map(|f| split(&f.corners, &x))
        .collect();
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            // +1 one way, −1 the other: a closed, consistently wound surface sums to zero.
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += if a < b { 1 } else { -1 };
        }
    }
    let open = edges.values().filter(|&&c| c != 0).count();
    if open > 0 {
        return Err(invalid(
            format!("{key}.shape.path"),
            format!(
                "{shown}: a solid needs a closed, consistently wound surface; {open} edge{} \
                 {} not shared by exactly two faces winding opposite ways",
                if open == 1 { "" } else { "s" },
                if open == 1 { "is" } else { "are" }
            ),
        ));
    }
    // The winding number's magnitude fills an inside-out mesh as well as any, but its
    // normals point in: drawn and exported, its faces show their backs.
    let mut warnings = Vec::new();
    let volume = enclosed_volume(&x, &triangles);
    if volume < 0.0 {
        warnings.push(format!(
            "{shown}: its faces wind inward (their normals point into the solid; the volume \
             they enclose by their winding is {:.3e} m³): it is filled all the same, but its \
             drawn and exported surface faces inward; flip the faces' winding in the program \
             that made it (Blender: Mesh ▸ Normals ▸ Recalculate Outside)",
            volume
        ));
    }
    let used: Vec<u32> = {
        let mut u: Vec<u32> = triangles.iter().flatten().copied().collect();
        u.sort_unstable();
        u.dedup();
        u
    };
    let (lo, hi) = used.iter().fold(
        (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), &v| (lo.inf(&x[v as usize]), hi.sup(&x[v as usize])),
    );
    let extent = hi - lo;
    if extent.min() < spacing {
        return Err(invalid(
            format!("{key}.shape.spacing"),
            format!(
                "{shown} is {:.4} × {:.4} × {:.4} m (scaled), smaller than a cell of {} m \
                 along some axis: give a smaller spacing",
                extent.x,
                extent.y,
                extent.z,
                hooke_core::Num(spacing)
            ),
        ));
    }
    let cells = extent.map(|e| (e / spacing).ceil().max(1.0) as usize);
    let count = (cells.x + 1)
        .checked_mul(cells.y + 1)
        .and_then(|n| n.checked_mul(cells.z + 1));
    if count.is_none_or(|n| n > limit) {
        return Err(invalid(
            format!("{key}.shape.spacing"),
            format!(
                "a lattice of {} × {} × {} cells would have more than {limit} particles: \
                 give a larger spacing",
                cells.x, cells.y, cells.z
            ),
        ));
    }
    let cell_of = |p: &Vec3| {
        let c = (p - lo) / spacing;
        [0, 1, 2].map(|d| (c[d].floor().max(0.0) as usize).min(cells[d] - 1))
    };
    let cell_index = |c: [usize; 3]| (c[0] * cells.y + c[1]) * cells.z + c[2];
    let mut filled = vec![false; cells.x * cells.y * cells.z];
    for &v in &used {
        filled[cell_index(cell_of(&x[v as usize]))] = true;
    }
    for i in 0..cells.x {
        for j in 0..cells.y {
            for k in 0..cells.z {
                let centre =
                    lo + Vec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * spacing;
                if winding(&centre, &x, &triangles) > 0.5 {
                    filled[cell_index([i, j, k])] = true;
                }
            }
        }
    }
    // Particles: the corners of filled cells, in the lattice's order.
    let nodes = Lattice {
        size: [cells.x + 1, cells.y + 1, cells.z + 1],
    };
    let mut particle = vec![u32::MAX; nodes.len()];
    let mut local = Vec::new();
    let corner =
        |c: [usize; 3], b: usize| [c[0] + (b >> 2 & 1), c[1] + (b >> 1 & 1), c[2] + (b & 1)];
    for i in 0..cells.x {
        for j in 0..cells.y {
            for k in 0..cells.z {
                if filled[cell_index([i, j, k])] {
                    for b in 0..8 {
                        particle[nodes.index(corner([i, j, k], b))] = 0;
                    }
                }
            }
        }
    }
    for (n, p) in particle.iter_mut().enumerate() {
        if *p == 0 {
            *p = local.len() as u32;
            let [a, b] = [nodes.size[1] * nodes.size[2], nodes.size[2]];
            let ijk = [n / a, n % a / b, n % b];
            local.push(lo + Vec3::new(ijk[0] as f64, ijk[1] as f64, ijk[2] as f64) * spacing);
        }
    }
    // A spring joins two particles of one filled cell (structural, shear) or two
    // structural springs in a line (bend).
    let in_filled_cell = |p: [usize; 3], q: [usize; 3]| {
        let lo_c = [0, 1, 2].map(|d| p[d].max(q[d]).saturating_sub(1));
        let hi_c = [0, 1, 2].map(|d| p[d].min(q[d]).min(cells[d] - 1));
        (lo_c[0]..=hi_c[0]).any(|i| {
            (lo_c[1]..=hi_c[1]).any(|j| (lo_c[2]..=hi_c[2]).any(|k| filled[cell_index([i, j, k])]))
        })
    };
    let ijk_of = |n: usize| {
        let [a, b] = [nodes.size[1] * nodes.size[2], nodes.size[2]];
        [n / a, n % a / b, n % b]
    };
    let mut springs = Vec::new();
    let mut structural = std::collections::HashSet::new();
    for kind in [SpringKind::Structural, SpringKind::Shear, SpringKind::Bend] {
        for e in nodes.edges(kind, spacing) {
            let (i, j) = (e.i as usize, e.j as usize);
            if particle[i] == u32::MAX || particle[j] == u32::MAX {
                continue;
            }
            let (p, q) = (ijk_of(i), ijk_of(j));
            let keep = match kind {
                SpringKind::Bend => {
                    let m = nodes.index([0, 1, 2].map(|d| (p[d] + q[d]) / 2));
                    structural.contains(&(i.min(m), i.max(m)))
                        && structural.contains(&(m.min(j), m.max(j)))
                }
                _ => in_filled_cell(p, q),
            };
            if keep {
                if kind == SpringKind::Structural {
                    structural.insert((i.min(j), i.max(j)));
                }
                springs.push((kind, particle[i], particle[j], e.rest));
            }
        }
    }
    // The lattice's outer faces: a cell face with a filled cell on one side only.
    let mut boundary = Vec::new();
    for i in 0..cells.x {
        for j in 0..cells.y {
            for k in 0..cells.z {
                if !filled[cell_index([i, j, k])] {
                    continue;
                }
                let c = [i, j, k];
                for axis in 0..3 {
                    for side in [0usize, 1] {
                        let mut n = c;
                        let outside = if side == 0 {
                            c[axis] == 0 || {
                                n[axis] -= 1;
                                !filled[cell_index(n)]
                            }
                        } else {
                            c[axis] + 1 == cells[axis] || {
                                n[axis] += 1;
                                !filled[cell_index(n)]
                            }
                        };
                        if !outside {
                            continue;
                        }
                        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                        let at = |du: usize, dv: usize| {
                            let mut q = c;
                            q[axis] += side;
                            q[u] += du;
                            q[v] += dv;
                            particle[nodes.index(q)]
                        };
                        let quad = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
                        // Wound counter-clockwise seen from outside.
                        if side == 1 {
                            boundary.push([quad[0], quad[1], quad[2]]);
                            boundary.push([quad[0], quad[2], quad[3]]);
                        } else {
                            boundary.push([quad[0], quad[2], quad[1]]);
                            boundary.push([quad[0], quad[3], quad[2]]);
                        }
                    }
                }
            }
        }
    }
    let vertices = x
        .iter()
        .map(|p| {
            let c = cell_of(p);
            let t = (p - lo) / spacing - Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64);
            let mut corners = [0u32; 8];
            let mut weights = [0.0; 8];
            for b in 0..8 {
                corners[b] = particle[nodes.index(corner(c, b))];
                let f = |bit: usize, s: f64| if b >> bit & 1 == 1 { s } else { 1.0 - s };
                weights[b] = f(2, t.x) * f(1, t.y) * f(0, t.z);
            }
            if corners.contains(&u32::MAX) {
                // A vertex in no face sits in a cell that may be empty: it stays put.
                SkinVertex::Fixed(*p)
            } else {
                SkinVertex::Embedded { corners, weights }
            }
        })
        .collect();
    let skin = Skin::of_file(mesh, vertices);
    Ok(Filled {
        local,
        springs,
        boundary,
        skin,
        warnings,
    })
}

/// The volume a closed surface of `triangles` encloses (positive when wound outward).
pub fn enclosed_volume(x: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| x[i as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

/// The winding number of a closed surface about `p`: 1 inside, 0 outside (the sum of the
/// triangles' signed solid angles over 4π, Van Oosterom and Strackee's formula).
fn winding(p: &Vec3, x: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    let mut sum = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|i| x[i as usize] - p);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let num = a.dot(&b.cross(&c));
        let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
        sum += 2.0 * num.atan2(den);
    }
    (sum / (4.0 * std::f64::consts::PI)).abs()
}
