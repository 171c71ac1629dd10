//! How much memory a scene will need, estimated from its description before anything is
//! built, so that a scene too large for the machine is refused in milliseconds with the key
//! to change, not after minutes of swapping.
//!
//! The costs per item are measured peaks of `hooke run SCENE --steps 1` (the build, the
//! stability estimate and one step, integrator workspaces included) on lattices of 40³ and
//! 80³ particles, grids of 500² and 1000² (with and without a contact thickness) and a
//! 70 MB OBJ table of 2 million triangles (14 bytes per file byte), rounded up: they
//! over-estimate those scenes by 3 to 20 %, which is the side to err on.

use crate::generators::Lattice;
use crate::spec::{ColliderShapeSpec, SceneSpec, ShapeSpec};
use hooke_core::SpringKind;
use std::path::Path;

/// Bytes per particle: state, masses, integrator stages, assembly and per-particle indices.
pub const BYTES_PER_PARTICLE: u64 = 450;
/// Bytes per spring: the spring, its copy in the assembly's layout and build temporaries.
pub const BYTES_PER_SPRING: u64 = 80;
/// Extra bytes per particle of a surface with a contact thickness: triangles, the hashed
/// grid and candidate lists.
pub const BYTES_PER_SURFACE_PARTICLE: u64 = 500;
/// Bytes per force-field node: the parsed values, the scene's copy and the built field.
pub const BYTES_PER_FIELD_NODE: u64 = 80;
/// Bytes per byte of an OBJ table file: tobj's buffers, the triangle mesh, its BVH and the
/// drawn copy.
pub const BYTES_PER_MESH_FILE_BYTE: u64 = 16;

/// Peak bytes per byte of a TOML scene file while it is read (toml's spanned document and
/// the scene built from it: 53 measured on a 21 MB file of spring pairs).
pub const READ_BYTES_PER_TOML_BYTE: u64 = 60;
/// Peak bytes per byte of a `.w` world while it is read (the text, the parsed vectors and
/// the scene made from them: 4.7 measured on a 120 MB world of resolution 200).
pub const READ_BYTES_PER_WORLD_BYTE: u64 = 6;

/// The peak memory of reading a scene file of `len` bytes, by its extension (`toml` or
/// `w`); zero for anything else.
///
/// ```
/// use hooke_scene::footprint::reading_bytes;
/// assert_eq!(reading_bytes("w", 1000), 6000);
/// assert_eq!(reading_bytes("obj", 1000), 0);
/// ```
pub fn reading_bytes(extension: &str, len: u64) -> u64 {
    match extension {
        "toml" => len.saturating_mul(READ_BYTES_PER_TOML_BYTE),
        "w" => len.saturating_mul(READ_BYTES_PER_WORLD_BYTE),
        _ => 0,
    }
}

/// A scene's estimated size and memory.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Footprint {
    /// Particles in all bodies.
    pub particles: u64,
    /// Springs, generated and explicit.
    pub springs: u64,
    /// Particles of bodies whose surface has a contact thickness.
    pub surface_particles: u64,
    /// Force-field nodes.
    pub field_nodes: u64,
    /// Bytes of OBJ files the colliders load.
    pub mesh_file_bytes: u64,
    /// The scene key that costs the most, and its bytes: what to change when the whole is
    /// too large (for example `body[0] 'cube'.shape.size`).
    pub largest: Option<(String, u64)>,
}

impl Footprint {
    /// Adds a body of `particles`, `springs` and `surface_particles`, noting its bytes
    /// under `key`.
    fn add_body(&mut self, key: String, particles: u64, springs: u64, surface_particles: u64) {
        self.particles = self.particles.saturating_add(particles);
        self.springs = self.springs.saturating_add(springs);
        self.surface_particles = self.surface_particles.saturating_add(surface_particles);
        let bytes = Footprint {
            particles,
            springs,
            surface_particles,
            ..Footprint::default()
        }
        .bytes();
        self.note(key, bytes);
    }

    /// The estimated peak memory in bytes.
    pub fn bytes(&self) -> u64 {
        self.particles
            .saturating_mul(BYTES_PER_PARTICLE)
            .saturating_add(self.springs.saturating_mul(BYTES_PER_SPRING))
            .saturating_add(
                self.surface_particles
                    .saturating_mul(BYTES_PER_SURFACE_PARTICLE),
            )
            .saturating_add(self.field_nodes.saturating_mul(BYTES_PER_FIELD_NODE))
            .saturating_add(
                self.mesh_file_bytes
                    .saturating_mul(BYTES_PER_MESH_FILE_BYTE),
            )
    }

    fn note(&mut self, key: String, bytes: u64) {
        if self.largest.as_ref().is_none_or(|(_, b)| bytes > *b) {
            self.largest = Some((key, bytes));
        }
    }
}

impl SceneSpec {
    /// Estimates the memory building and running this scene takes, without building it.
    /// Mesh files are looked up relative to `base` (as [`SceneSpec::build`] does); a file
    /// that cannot be found counts as empty (the build reports it).
    ///
    /// ```
    /// let spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    /// let f = spec.footprint(std::path::Path::new("."));
    /// assert_eq!(f.particles, 625);
    /// assert!(f.bytes() > 500_000 && f.bytes() < 2_000_000);
    /// ```
    pub fn footprint(&self, base: &Path) -> Footprint {
        let mut f = Footprint::default();
        for (b, body) in self.bodies.iter().enumerate() {
            let key = format!("body[{b}] '{}'", body.name);
            if let Some(path) = body.shape.mesh_path() {
                let (particles, springs) = mesh_estimate(&body.shape, path, base);
                // A solid's lattice grows with its spacing, a cloth with its mesh.
                let part = match body.shape {
                    ShapeSpec::Solid { .. } => "spacing",
                    _ => "path",
                };
                f.add_body(format!("{key}.shape.{part}"), particles, springs, particles);
                continue;
            }
            let (lattice, size_key) = match &body.shape {
                ShapeSpec::Chain { count, .. } => (
                    Lattice {
                        size: [*count, 1, 1],
                    },
                    "count",
                ),
                ShapeSpec::Grid { size, .. } => (
                    Lattice {
                        size: [size[0], 1, size[1]],
                    },
                    "size",
                ),
                ShapeSpec::Lattice { size, .. } => (Lattice { size: *size }, "size"),
                ShapeSpec::Points { positions } => (
                    Lattice {
                        size: [positions.len(), 1, 1],
                    },
                    "positions",
                ),
                ShapeSpec::Mesh { .. } | ShapeSpec::Solid { .. } => continue,
            };
            let particles = lattice
                .size
                .iter()
                .fold(1u64, |a, &n| a.saturating_mul(n as u64));
            let generated = !matches!(body.shape, ShapeSpec::Points { .. });
            let mut springs = body.springs.pairs.len() as u64;
            let material = body.material.as_ref().and_then(|m| m.resolve("").ok());
            if let (Some(m), ShapeSpec::Grid { size, .. }) = (material, &body.shape) {
                springs = springs.saturating_add(m.spring_count(*size));
            } else if generated {
                for kind in [SpringKind::Structural, SpringKind::Shear, SpringKind::Bend] {
                    if body.springs.params(kind).is_some() {
                        springs = springs.saturating_add(lattice.edge_count(kind) as u64);
                    }
                }
            }
            // A grid has a surface with a thickness unless it is set to zero; in air, grids
            // and lattices keep their triangles and per-triangle forces, which cost about
            // what a contact surface does (an upper bound for a lattice, whose surface is
            // only its skin).
            let has_triangles = matches!(
                body.shape,
                ShapeSpec::Grid { .. } | ShapeSpec::Lattice { .. }
            );
            let surface = (matches!(body.shape, ShapeSpec::Grid { .. })
                && body.thickness.is_none_or(|t| t.get() > 0.0))
                || (has_triangles && self.simulation.air.is_some());
            let surface_particles = if surface { particles } else { 0 };
            let key = if body.springs.pairs.len() as u64 * 2 > springs {
                format!("{key}.springs.pairs")
            } else {
                format!("{key}.shape.{size_key}")
            };
            f.add_body(key, particles, springs, surface_particles);
        }
        if let Some(field) = &self.force_field {
            let r = field.resolution as u64;
            f.field_nodes = r.saturating_mul(r).saturating_mul(r);
            f.note(
                "force_field.resolution".into(),
                f.field_nodes.saturating_mul(BYTES_PER_FIELD_NODE),
            );
        }
        for (c, collider) in self.colliders.iter().enumerate() {
            if let ColliderShapeSpec::Mesh { path, .. } = &collider.shape {
                let bytes = crate::colliders::mesh_file_len(path, base);
                f.mesh_file_bytes = f.mesh_file_bytes.saturating_add(bytes);
                f.note(
                    format!("collider[{c}].shape.path"),
                    bytes.saturating_mul(BYTES_PER_MESH_FILE_BYTE),
                );
            }
        }
        f
    }
}

/// Particles and springs a body made from the mesh at `path` will have, estimated from the
/// file without building it: a vertex per `v` line and about nine springs each for a cloth
/// (edges and bending pairs); the lattice over the vertices' bounding box and thirteen
/// springs a particle for a solid. A file that cannot be read counts as empty.
fn mesh_estimate(shape: &ShapeSpec, path: &str, base: &Path) -> (u64, u64) {
    let Ok((text, _)) = crate::colliders::mesh_text(path, base) else {
        return (0, 0);
    };
    let vertices = text.lines().filter(|l| l.starts_with("v ")).map(|l| {
        let p: Vec<f64> = l
            .split_whitespace()
            .skip(1)
            .filter_map(|w| w.parse().ok())
            .collect();
        [0, 1, 2].map(|d| p.get(d).copied().unwrap_or(0.0))
    });
    match shape {
        ShapeSpec::Solid { scale, spacing, .. } => {
            let (lo, hi) = vertices.fold(
                ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
                |(lo, hi), p| {
                    (
                        [0, 1, 2].map(|d| lo[d].min(p[d])),
                        [0, 1, 2].map(|d| hi[d].max(p[d])),
                    )
                },
            );
            let cells = (0..3)
                .map(|d| ((hi[d] - lo[d]).max(0.0) * scale[d].get() / spacing.get()).ceil() + 1.0)
                .product::<f64>();
            let n = if cells.is_finite() {
                cells.min(u64::MAX as f64) as u64
            } else {
                0
            };
            (n, n.saturating_mul(13))
        }
        _ => {
            let n = vertices.count() as u64;
            (n, n.saturating_mul(9))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::BUILTINS;

    /// The estimate counts exactly what the build makes, for every built-in and for a
    /// lattice, a grid and a chain of odd sizes.
    #[test]
    fn counts_match_the_built_scenes() {
        let mut specs: Vec<SceneSpec> = BUILTINS.iter().map(|(_, make)| make()).collect();
        for size in [[3, 5, 7], [1, 9, 2], [2, 2, 2]] {
            let mut spec = crate::builtin::builtin("jello-cube").unwrap();
            if let ShapeSpec::Lattice { size: s, .. } = &mut spec.bodies[0].shape {
                *s = size;
            }
            specs.push(spec);
        }
        specs.push(crate::workload::cloth(17));
        for spec in specs {
            let f = spec.footprint(Path::new("."));
            let scene = spec.build(Path::new(".")).unwrap();
            let sim = &scene.simulation;
            assert_eq!(f.particles as usize, sim.particles().len(), "{}", spec.name);
            assert_eq!(
                f.springs as usize,
                sim.model().springs.len(),
                "{}",
                spec.name
            );
            let surfaces: usize = sim.model().surfaces.iter().map(|s| s.particles.len()).sum();
            assert_eq!(f.surface_particles as usize, surfaces, "{}", spec.name);
            assert!(f.largest.is_some());
        }
    }

    /// A lattice too large for any machine is estimated without overflow, and the key to
    /// change is its size.
    #[test]
    fn huge_scenes_saturate_and_name_their_key() {
        let mut spec = crate::builtin::builtin("jello-cube").unwrap();
        if let ShapeSpec::Lattice { size, .. } = &mut spec.bodies[0].shape {
            *size = [usize::MAX / 2, 3, 3];
        }
        let f = spec.footprint(Path::new("."));
        assert_eq!(f.bytes(), u64::MAX);
        assert_eq!(f.largest.unwrap().0, "body[0] 'jelly'.shape.size");
    }
}
