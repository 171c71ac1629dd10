//! One body's particles, masses and springs: from its springs (`[body.springs]`, a mass per
//! particle) or from a material (`[body.material]`), and its keyframed pins.

pub(crate) mod mesh;

use crate::error::{BuildError, invalid};
use crate::generators::Lattice;
use crate::limits::MAX_PARTICLES;
use crate::scene::Topology;
use crate::spec::*;
use hooke_core::{Particles, PinMotion, Spring, SpringKind, Vec3};

/// A body's particles in its own frame, their masses, springs and shape.
pub(crate) struct BuiltBody {
    pub(crate) local: Vec<Vec3>,
    /// Per particle, kg.
    pub(crate) masses: Vec<f64>,
    pub(crate) springs: Vec<Spring>,
    pub(crate) topology: Topology,
    /// The surface triangles (indices within the body) of a body made from a mesh; the
    /// generated shapes' come from their topology.
    pub(crate) triangles: Option<Vec<[u32; 3]>>,
    /// The user's mesh, for a body made from one (particle indices within the body).
    pub(crate) skin: Option<crate::skin::Skin>,
    /// The pinned particles, within the body.
    pub(crate) pins: Vec<usize>,
    /// What building did that the user should hear of.
    pub(crate) warnings: Vec<String>,
}

/// Builds body `key` (its particles numbered from `offset`; mesh files found from `base`).
pub(crate) fn build_body(
    body: &BodySpec,
    key: &str,
    offset: usize,
    base: &std::path::Path,
) -> Result<BuiltBody, BuildError> {
    let scaled = |s: &[crate::spec::Positive; 3]| Vec3::new(s[0].get(), s[1].get(), s[2].get());
    match &body.shape {
        ShapeSpec::Mesh { path, scale, weld } => {
            return crate::body::mesh::cloth(
                body,
                key,
                offset,
                base,
                (path, scaled(scale), weld.map(|w| w.get())),
            );
        }
        ShapeSpec::Solid {
            path,
            scale,
            spacing,
        } => {
            return crate::body::mesh::jelly(
                body,
                key,
                offset,
                base,
                (path, scaled(scale), spacing.get()),
            );
        }
        _ => {}
    }
    if let Some(material) = &body.material {
        return material_body(body, material, key, offset);
    }
    let mass = need_mass(body, key)?;
    let mut built = spring_body(body, key, offset)?;
    built.masses = vec![mass; built.local.len()];
    built.pins = crate::body::mesh::region_pins(body, key, &built.local, None)?;
    Ok(built)
}

/// A body's moving pins (docs/physics.md §1.2): its pinned particles (`built.pins`, within
/// the body, whose first particle is `start`), moved rigidly by `motion`'s keys, or each to
/// its own vertex's point in `motion`'s cache (one point per vertex of the body: a mesh
/// body's file vertices in order, a generated body's particles), placed as the body is.
pub(crate) fn pin_motion(
    built: &BuiltBody,
    body: &BodySpec,
    key: &str,
    start: usize,
    particles: &Particles,
    base: &std::path::Path,
) -> Result<PinMotion, BuildError> {
    let motion = body
        .pin_motion
        .as_ref()
        .expect("called for a body with a pin_motion");
    let at = format!("{key}.pin_motion");
    if built.pins.is_empty() {
        return Err(invalid(
            at,
            "it moves the body's pinned particles, and the body has none: give `pins`",
        ));
    }
    let mut pins = built.pins.clone();
    pins.sort_unstable();
    pins.dedup();
    let ids: Vec<u32> = pins.iter().map(|&p| (start + p) as u32).collect();
    let Some((cache, fps)) = crate::colliders::cache_of(motion, &at)? else {
        let keys = crate::colliders::keyframes(motion, &at)?;
        return Ok(PinMotion::new(ids, &particles.x, keys));
    };
    let scale = match &body.shape {
        ShapeSpec::Mesh { scale, .. } => Vec3::new(scale[0].get(), scale[1].get(), scale[2].get()),
        ShapeSpec::Solid { .. } => {
            return Err(invalid(
                format!("{at}.cache"),
                "a jelly's pinned particles are its lattice's, which no mesh vertex is: move \
                 them with `keys`",
            ));
        }
        _ => Vec3::repeat(1.0),
    };
    // Each pinned particle follows the first of the vertices that are it (welded ones
    // share a particle).
    let (count, vertex): (usize, Vec<usize>) = match &built.skin {
        Some(skin) => {
            let mut first = vec![usize::MAX; built.local.len()];
            for (v, s) in skin.vertices.iter().enumerate().rev() {
                if let crate::skin::SkinVertex::Particle(p) = s {
                    first[*p as usize] = v;
                }
            }
            (
                skin.vertices.len(),
                pins.iter().map(|&p| first[p]).collect(),
            )
        }
        None => (built.local.len(), pins.clone()),
    };
    let placement = hooke_collide::Placement {
        translate: vec3(&body.origin),
        rotate: vec3(&body.rotate),
        scale,
    };
    let frames = hooke_collide::VertexCache::read(&base.join(cache), count, fps, &placement)
        .map_err(|source| BuildError::Mesh {
            key: format!("{at}.cache"),
            source,
        })?;
    let samples = (0..frames.len())
        .map(|k| vertex.iter().map(|&v| frames.sample(k)[v]).collect())
        .collect();
    Ok(PinMotion::track(ids, samples, frames.interval()))
}

/// A body's `mass` per particle, which a body without a material must give.
pub(crate) fn need_mass(body: &BodySpec, key: &str) -> Result<f64, BuildError> {
    body.mass.map(|m| m.get()).ok_or_else(|| {
        invalid(
            format!("{key}.mass"),
            "missing: give `mass` (kg per particle) and `springs`, or a `[body.material]`",
        )
    })
}

/// Refuses `mass` and `springs` beside a material, which gives both.
pub(crate) fn refuse_mass_and_springs(body: &BodySpec, key: &str) -> Result<(), BuildError> {
    let given: Vec<&str> = [
        ("mass", body.mass.is_some()),
        ("springs", !body.springs.is_empty()),
    ]
    .iter()
    .filter(|(_, on)| *on)
    .map(|(name, _)| *name)
    .collect();
    if !given.is_empty() {
        Err(invalid(
            format!("{key}.material"),
            format!(
                "a material gives the masses and springs: remove {} (or the material)",
                given
                    .iter()
                    .map(|k| format!("`{k}`"))
                    .collect::<Vec<_>>()
                    .join(" and ")
            ),
        ))
    } else {
        Ok(())
    }
}

/// A grid given as a material: its masses and springs derived for its spacing.
fn material_body(
    body: &BodySpec,
    material: &crate::spec::MaterialSpec,
    key: &str,
    offset: usize,
) -> Result<BuiltBody, BuildError> {
    refuse_mass_and_springs(body, key)?;
    let ShapeSpec::Grid { size, spacing } = &body.shape else {
        return Err(invalid(
            format!("{key}.material"),
            "a material is for a cloth: the body's shape must be a `grid`",
        ));
    };
    let material = material.resolve(&format!("{key}.material"))?;
    let mut built = spring_body(body, key, offset)?;
    built.masses = material.masses(*size, spacing.get());
    built.pins = crate::body::mesh::region_pins(body, key, &built.local, None)?;
    let n = built.local.len();
    let mut held = vec![false; n];
    for &p in built.pins.iter().filter(|&&p| p < n) {
        held[p] = true;
    }
    let pinned = |p: usize| held[p];
    built.springs = material.springs(*size, spacing.get(), offset, &pinned);
    Ok(built)
}

/// A body's particles and the springs its `springs` table gives (masses left empty).
fn spring_body(body: &BodySpec, key: &str, offset: usize) -> Result<BuiltBody, BuildError> {
    let (lattice, h, topology) = match &body.shape {
        ShapeSpec::Chain { count, spacing } => (
            Lattice {
                size: [*count, 1, 1],
            },
            spacing.get(),
            Topology::Chain,
        ),
        ShapeSpec::Grid { size, spacing } => (
            Lattice {
                size: [size[0], 1, size[1]],
            },
            spacing.get(),
            Topology::Grid(*size),
        ),
        ShapeSpec::Lattice { size, spacing } => (
            Lattice { size: *size },
            spacing.get(),
            Topology::Lattice(*size),
        ),
        ShapeSpec::Mesh { .. } | ShapeSpec::Solid { .. } => unreachable!("built from a mesh"),
        ShapeSpec::Points { positions } => {
            let local: Vec<Vec3> = positions.iter().map(vec3).collect();
            if body.springs.structural.is_some()
                || body.springs.shear.is_some()
                || body.springs.bend.is_some()
            {
                return Err(invalid(
                    format!("{key}.springs"),
                    "points have no topology: use explicit `pairs`, not structural/shear/bend",
                ));
            }
            let springs = pairs(body, key, &local, offset)?;
            return Ok(BuiltBody {
                local,
                masses: Vec::new(),
                springs,
                topology: Topology::Points,
                triangles: None,
                skin: None,
                pins: Vec::new(),
                warnings: Vec::new(),
            });
        }
    };
    let count = lattice
        .size
        .iter()
        .try_fold(1usize, |acc, &n| acc.checked_mul(n));
    if !count.is_some_and(|n| (1..=MAX_PARTICLES).contains(&n)) {
        let total = count.map_or("more than 2^64".to_string(), |n| n.to_string());
        let (field, found) = match &body.shape {
            ShapeSpec::Chain { count, .. } => ("count", format!("{count}")),
            ShapeSpec::Grid { size, .. } => ("size", format!("{size:?} ({total} particles)")),
            ShapeSpec::Lattice { size, .. } => ("size", format!("{size:?} ({total} particles)")),
            ShapeSpec::Points { positions } => ("positions", format!("{} points", positions.len())),
            ShapeSpec::Mesh { .. } | ShapeSpec::Solid { .. } => unreachable!("built from a mesh"),
        };
        return Err(invalid(
            format!("{key}.shape.{field}"),
            format!("expected 1 to {MAX_PARTICLES} particles, found {found}"),
        ));
    }
    let local = lattice.positions(h);
    let mut springs = Vec::new();
    for kind in [SpringKind::Structural, SpringKind::Shear, SpringKind::Bend] {
        if let Some(p) = body.springs.params(kind) {
            springs.extend(lattice.edges(kind, h).into_iter().map(|e| Spring {
                i: (offset + e.i as usize) as u32,
                j: (offset + e.j as usize) as u32,
                rest: e.rest,
                ks: p.ks.get(),
                kd: p.kd.get(),
                kind,
            }));
        }
    }
    springs.extend(pairs(body, key, &local, offset)?);
    Ok(BuiltBody {
        local,
        masses: Vec::new(),
        springs,
        topology,
        triangles: None,
        skin: None,
        pins: Vec::new(),
        warnings: Vec::new(),
    })
}

/// The explicit `[[body.springs.pairs]]` of a body whose particles are at `local`.
pub(crate) fn pairs(
    body: &BodySpec,
    key: &str,
    local: &[Vec3],
    offset: usize,
) -> Result<Vec<Spring>, BuildError> {
    let n = local.len();
    body.springs
        .pairs
        .iter()
        .enumerate()
        .map(|(k, p)| {
            if p.i >= n || p.j >= n || p.i == p.j {
                return Err(invalid(
                    format!("{key}.springs.pairs[{k}]"),
                    format!(
                        "expected two different particles below {n}, found i = {}, j = {}",
                        p.i, p.j
                    ),
                ));
            }
            let rest = p
                .rest
                .map_or_else(|| (local[p.i] - local[p.j]).norm(), |r| r.get());
            Ok(Spring {
                i: (offset + p.i) as u32,
                j: (offset + p.j) as u32,
                rest,
                ks: p.ks.get(),
                kd: p.kd.get(),
                kind: SpringKind::Other,
            })
        })
        .collect()
}
