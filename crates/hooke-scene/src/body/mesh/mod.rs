//! Bodies made from the user's meshes: a cloth from any surface (`kind = "mesh"`) and a
//! jelly filling any closed one (`kind = "solid"`); docs/physics.md §1.1 and docs/scenes.md.

pub(crate) mod bending;
pub(crate) mod membrane;
pub(crate) mod sheet;
pub(crate) mod solid;

use crate::body::{BuiltBody, need_mass, refuse_mass_and_springs};
use crate::error::{BuildError, invalid};
use crate::limits::MAX_PARTICLES;
use crate::material::Material;
use crate::scene::Topology;
use crate::spec::{BodySpec, PinRegion, Pins, SpringParams};
use hooke_collide::PolygonMesh;
use hooke_core::{Spring, SpringKind, Vec3};
use sheet::{Sheet, canonical};
use std::collections::BTreeMap;
use std::path::Path;

/// Reads the OBJ a mesh or solid body names, against `base`.
fn read(
    path: &str,
    base: &Path,
    key: &str,
) -> Result<(PolygonMesh, std::path::PathBuf), BuildError> {
    let (text, full) =
        crate::colliders::mesh_text(path, base).map_err(|source| BuildError::Mesh {
            key: format!("{key}.shape.path"),
            source,
        })?;
    let mesh =
        PolygonMesh::parse(&text, &full, MAX_PARTICLES).map_err(|source| BuildError::Mesh {
            key: format!("{key}.shape.path"),
            source,
        })?;
    Ok((mesh, full))
}

/// A cloth from the mesh at `path`: its particles, masses, springs, triangles, pins and the
/// user's mesh, particles numbered from `offset`.
pub(crate) fn cloth(
    body: &BodySpec,
    key: &str,
    offset: usize,
    base: &Path,
    (path, scale, weld): (&str, Vec3, Option<f64>),
) -> Result<BuiltBody, BuildError> {
    let (mesh, full) = read(path, base, key)?;
    let mut sheet = sheet::sheet(mesh, &full, key, scale, weld)?;
    let pins = mesh_pins(body, key, &sheet)?;
    let (masses, springs) = match &body.material {
        Some(m) => {
            refuse_mass_and_springs(body, key)?;
            let material = m.resolve(&format!("{key}.material"))?;
            (
                fabric_masses(&sheet, &material),
                fabric_springs(&mut sheet, &material, offset, &pins, &full),
            )
        }
        None => {
            let mass = need_mass(body, key)?;
            (
                vec![mass; sheet.local.len()],
                plain_springs(&sheet, body, offset),
            )
        }
    };
    Ok(BuiltBody {
        masses,
        springs,
        topology: Topology::Mesh,
        triangles: Some(sheet.triangles.clone()),
        skin: Some(sheet.skin),
        pins,
        warnings: sheet.warnings,
        local: sheet.local,
    })
}

/// A jelly filling the closed mesh at `path` with a lattice of `spacing`.
pub(crate) fn jelly(
    body: &BodySpec,
    key: &str,
    offset: usize,
    base: &Path,
    (path, scale, spacing): (&str, Vec3, f64),
) -> Result<BuiltBody, BuildError> {
    if body.material.is_some() {
        return Err(invalid(
            format!("{key}.material"),
            "a material is for a cloth; a solid takes `mass` and `[body.springs]`",
        ));
    }
    let mass = need_mass(body, key)?;
    let (mesh, full) = read(path, base, key)?;
    let filled = solid::fill(&mesh, &full, key, scale, spacing, MAX_PARTICLES)?;
    let n = filled.local.len();
    let file: Vec<Vec3> = filled
        .local
        .iter()
        .map(|p| p.component_div(&scale))
        .collect();
    let pins = region_pins(body, key, &file, None)?;
    let mut springs = Vec::new();
    for (kind, i, j, rest) in &filled.springs {
        if let Some(p) = body.springs.params(*kind) {
            springs.push(spring(
                offset,
                (*i, *j),
                *rest,
                p.ks.get(),
                p.kd.get(),
                *kind,
            ));
        }
    }
    springs.extend(crate::body::pairs(body, key, &filled.local, offset)?);
    Ok(BuiltBody {
        masses: vec![mass; n],
        springs,
        topology: Topology::Solid,
        triangles: Some(filled.boundary),
        skin: Some(filled.skin),
        pins,
        warnings: filled.warnings,
        local: filled.local,
    })
}

fn spring(
    offset: usize,
    (i, j): (u32, u32),
    rest: f64,
    ks: f64,
    kd: f64,
    kind: SpringKind,
) -> Spring {
    Spring {
        i: offset as u32 + i,
        j: offset as u32 + j,
        rest,
        ks,
        kd,
        kind,
    }
}

/// Each particle's mass: the density times an equal share of each face's area.
fn fabric_masses(sheet: &Sheet, m: &Material) -> Vec<f64> {
    sheet::vertex_shares(&sheet.local, &sheet.polygons, m.density)
}

/// The membrane springs of each face (its sides, a quad's diagonals, an n-gon's fan),
/// `(i, j) → (ks, rest, kind)` summed over the faces that share them.
fn membrane_springs(sheet: &Sheet, m: &Material) -> BTreeMap<(u32, u32), (f64, f64, SpringKind)> {
    let x = &sheet.local;
    let mut out: BTreeMap<(u32, u32), (f64, f64, SpringKind)> = BTreeMap::new();
    for p in sheet.polygons.iter().map(|p| canonical(p)) {
        // A quad is one element: its sides and both diagonals. Larger polygons are fans of
        // triangles (from the lowest-numbered corner), each its own element.
        let elements: Vec<Vec<u32>> = if p.len() <= 4 {
            vec![p.clone()]
        } else {
            (1..p.len() - 1)
                .map(|k| vec![p[0], p[k], p[k + 1]])
                .collect()
        };
        for e in elements {
            let mut pairs: Vec<((u32, u32), SpringKind)> = (0..e.len())
                .map(|k| ((e[k], e[(k + 1) % e.len()]), SpringKind::Structural))
                .collect();
            if e.len() == 4 {
                pairs.push(((e[0], e[2]), SpringKind::Shear));
                pairs.push(((e[1], e[3]), SpringKind::Shear));
            }
            let mut normal = Vec3::zeros();
            for k in 0..e.len() {
                normal += x[e[k] as usize].cross(&x[e[(k + 1) % e.len()] as usize]);
            }
            let area = 0.5 * normal.norm();
            let normal = normal.normalize();
            let ends: Vec<(Vec3, Vec3)> = pairs
                .iter()
                .map(|((a, b), _)| (x[*a as usize], x[*b as usize]))
                .collect();
            let ks = membrane::fit(&ends, area, &normal, m.stretch, m.shear);
            for (((a, b), kind), k) in pairs.into_iter().zip(ks) {
                let rest = (x[a as usize] - x[b as usize]).norm();
                let entry = out.entry((a.min(b), a.max(b))).or_insert((0.0, rest, kind));
                entry.0 += k;
            }
        }
    }
    out
}

/// A fabric's springs on a mesh: the membrane (damped `damping · ks`) and the bending as
/// zero-rest-length springs (undamped), as docs/physics.md §1.1 states. A mesh with slivers
/// is told that its bending is fitted to the points.
fn fabric_springs(
    sheet: &mut Sheet,
    m: &Material,
    offset: usize,
    pins: &[usize],
    path: &Path,
) -> Vec<Spring> {
    let mut out: Vec<Spring> = membrane_springs(sheet, m)
        .into_iter()
        .filter(|(_, (k, ..))| *k > 0.0)
        .map(|(pair, (k, rest, kind))| spring(offset, pair, rest, k, m.damping * k, kind))
        .collect();
    if m.bending > 0.0 {
        let mut held = vec![false; sheet.local.len()];
        let n = held.len();
        for &p in pins.iter().filter(|&&p| p < n) {
            held[p] = true;
        }
        let (bend, steepest) = bending::springs(&sheet.local, &sheet.polygons, m.bending, &|p| {
            held[p as usize]
        });
        if let Some(steepest) = steepest {
            sheet.warnings.push(format!(
                "{}: slivers (a triangle {} times as long as it is high, over {}): its \
                 bending is fitted to each vertex's neighbours rather than taken on hinges \
                 (docs/physics.md §1.1, \"Bending on slivers\")",
                path.display(),
                steepest.round(),
                bending::SLIVER
            ));
        }
        out.extend(
            bend.into_iter()
                .map(|(pair, k)| spring(offset, pair, 0.0, k, 0.0, SpringKind::Bend)),
        );
    }
    out
}

/// A mesh's springs from `[body.springs]`: structural on the faces' sides, shear on quads'
/// diagonals and larger polygons' fans, bend across each side two faces share (between the
/// corners facing it), rest lengths as the mesh gives them.
fn plain_springs(sheet: &Sheet, body: &BodySpec, offset: usize) -> Vec<Spring> {
    let x = &sheet.local;
    let mut by_kind: BTreeMap<(u32, u32), SpringKind> = BTreeMap::new();
    let mut sides: BTreeMap<(u32, u32), Vec<u32>> = BTreeMap::new();
    for p in sheet.polygons.iter().map(|p| canonical(p)) {
        for k in 0..p.len() {
            let (a, b) = (p[k], p[(k + 1) % p.len()]);
            by_kind.insert((a.min(b), a.max(b)), SpringKind::Structural);
        }
        let diagonals: Vec<(u32, u32)> = if p.len() == 4 {
            vec![(p[0], p[2]), (p[1], p[3])]
        } else {
            (2..p.len().saturating_sub(1))
                .map(|k| (p[0], p[k]))
                .collect()
        };
        for (a, b) in diagonals {
            by_kind
                .entry((a.min(b), a.max(b)))
                .or_insert(SpringKind::Shear);
        }
    }
    for t in &sheet.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if by_kind.get(&(a.min(b), a.max(b))) == Some(&SpringKind::Structural) {
                sides
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(t[(k + 2) % 3]);
            }
        }
    }
    for opposite in sides.values() {
        if let [c, d] = opposite[..] {
            by_kind
                .entry((c.min(d), c.max(d)))
                .or_insert(SpringKind::Bend);
        }
    }
    let param = |kind| -> Option<SpringParams> { body.springs.params(kind) };
    let mut out: Vec<Spring> = by_kind
        .into_iter()
        .filter_map(|((a, b), kind)| {
            let p = param(kind)?;
            let rest = (x[a as usize] - x[b as usize]).norm();
            Some(spring(offset, (a, b), rest, p.ks.get(), p.kd.get(), kind))
        })
        .collect();
    out.sort_by_key(|s| (s.kind as u8, s.i, s.j));
    out
}

/// A mesh's pins: the file's vertex indices, a region in the file's coordinates, or a group.
fn mesh_pins(body: &BodySpec, key: &str, sheet: &Sheet) -> Result<Vec<usize>, BuildError> {
    if let Pins::Indices(list) = &body.pins {
        let n = sheet.particle_of.len();
        return list
            .iter()
            .enumerate()
            .map(|(k, &v)| match sheet.particle_of.get(v) {
                Some(Some(p)) => Ok(*p as usize),
                Some(None) => Err(invalid(
                    format!("{key}.pins[{k}]"),
                    format!("vertex {v} is in no face, so it is no particle to pin"),
                )),
                None => Err(invalid(
                    format!("{key}.pins[{k}]"),
                    format!(
                        "vertex {v} does not exist; the mesh has {n} (0 to {})",
                        n - 1
                    ),
                )),
            })
            .collect();
    }
    region_pins(body, key, &sheet.file, Some(sheet))
}

/// The particles in `pins`'s region, by their coordinates `at` (the body's own), or in a
/// group of `sheet`'s faces.
pub(crate) fn region_pins(
    body: &BodySpec,
    key: &str,
    at: &[Vec3],
    sheet: Option<&Sheet>,
) -> Result<Vec<usize>, BuildError> {
    let region: &PinRegion = match &body.pins {
        Pins::Indices(list) => return Ok(list.clone()),
        Pins::Region(r) => r,
    };
    let given = [
        region.aabb.is_some(),
        region.sphere.is_some(),
        region.group.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(invalid(
            format!("{key}.pins"),
            "give exactly one of `box`, `sphere` and `group`",
        ));
    }
    let picked: Vec<usize> = if let Some([a, b]) = &region.aabb {
        let (lo, hi) = (crate::spec::vec3(a), crate::spec::vec3(b));
        // Corners given the wrong way round are most likely a typo in one of them: a box
        // made of them anyway may hold far more than was meant.
        if let Some(d) = (0..3).find(|&d| lo[d] > hi[d]) {
            let axis = ["x", "y", "z"][d];
            return Err(invalid(
                format!("{key}.pins.box"),
                format!(
                    "the first corner is the lowest and the second the highest, but {axis} \
                     goes from {} down to {}: swap them",
                    hooke_core::Num(lo[d]),
                    hooke_core::Num(hi[d])
                ),
            ));
        }
        (0..at.len())
            .filter(|&p| (0..3).all(|d| at[p][d] >= lo[d] && at[p][d] <= hi[d]))
            .collect()
    } else if let Some(s) = &region.sphere {
        let r = s.radius.get();
        if r <= 0.0 {
            return Err(invalid(
                format!("{key}.pins.sphere.radius"),
                format!(
                    "a ball of pins needs a radius above zero, found {}",
                    hooke_core::Num(r)
                ),
            ));
        }
        let c = crate::spec::vec3(&s.center);
        (0..at.len()).filter(|&p| (at[p] - c).norm() <= r).collect()
    } else {
        let name = region.group.as_deref().unwrap_or_default();
        let Some(sheet) = sheet else {
            return Err(invalid(
                format!("{key}.pins.group"),
                "only a cloth made from a mesh (kind = \"mesh\") has groups",
            ));
        };
        let Some(g) = sheet.groups.iter().position(|n| n == name) else {
            return Err(invalid(
                format!("{key}.pins.group"),
                format!(
                    "the mesh has no group '{name}'; its groups: {}",
                    if sheet.groups.is_empty() {
                        "none".to_string()
                    } else {
                        sheet.groups.join(", ")
                    }
                ),
            ));
        };
        let mut out: Vec<usize> = sheet
            .polygons
            .iter()
            .zip(&sheet.polygon_groups)
            .filter(|(_, gs)| gs.contains(&(g as u32)))
            .flat_map(|(p, _)| p.iter().map(|&v| v as usize))
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    };
    if picked.is_empty() {
        return Err(invalid(
            format!("{key}.pins"),
            "the region holds no particle of the body (a region is in the body's own \
             coordinates; a mesh's are the file's, before `scale`)",
        ));
    }
    Ok(picked)
}
