//! From a scene description to a ready-to-step simulation.

use crate::generators::Lattice;
use crate::spec::*;
use hooke_collide::{BoxInterior, Cylinder, MeshError, Placement, Plane, TriMeshCollider};
use hooke_core::{
    Collider, ColliderSlot, DEFAULT_CLOTH_THICKNESS, DEFAULT_SURFACE_FRICTION, ForceField, Model,
    Particles, Response, Simulation, Spring, SpringKind, Surface, Vec3,
};
use hooke_core::{Num, SANE_BOUND};
use nalgebra::Rotation3;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Most particles a scene may have (2048²): beyond this a typo (an extra zero in a size)
/// would exhaust memory before anything useful happened. A lattice this large carries about
/// 13 springs per particle, some 3 GB with the solver's buffers.
pub const MAX_PARTICLES: usize = 1 << 22;

/// Most steps a run may take: a billion steps is half an hour of the 12-bead chain and days
/// of the cloth on the table; more is a mistake in `steps`, `duration` or `dt`.
pub const MAX_STEPS: u64 = 1_000_000_000;

/// Particles a shape will have, or `None` when the count overflows.
fn particle_count(shape: &ShapeSpec) -> Option<usize> {
    match shape {
        ShapeSpec::Chain { count, .. } => Some(*count),
        ShapeSpec::Grid { size, .. } => size[0].checked_mul(size[1]),
        ShapeSpec::Lattice { size, .. } => size[0].checked_mul(size[1])?.checked_mul(size[2]),
        ShapeSpec::Points { positions } => Some(positions.len()),
    }
}

/// Meshes shipped inside Hooke, addressable as `builtin:NAME` from any scene file.
pub const BUILTIN_MESHES: [(&str, &str); 2] = [
    (
        "table.obj",
        include_str!("../../../assets/meshes/table.obj"),
    ),
    (
        "square-table.obj",
        include_str!("../../../assets/meshes/square-table.obj"),
    ),
];

/// Why a scene description cannot be simulated.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// A value is inconsistent with the rest of the scene.
    #[error("{key}: {message}")]
    Invalid {
        /// Where in the scene, e.g. `body[1].pins[3]`.
        key: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A mesh could not be loaded (the mesh error follows in the error's chain).
    #[error("{key}")]
    Mesh {
        /// Where in the scene.
        key: String,
        /// The mesh error (names the file and, where it can, the line).
        source: MeshError,
    },
}

fn invalid(key: impl Into<String>, message: impl Into<String>) -> BuildError {
    BuildError::Invalid {
        key: key.into(),
        message: message.into(),
    }
}

/// How a body's particles are arranged, for drawing surfaces and picking subsets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Topology {
    /// A chain of particles.
    Chain,
    /// A cloth grid `[nx, nz]`.
    Grid([usize; 2]),
    /// A jelly lattice `[nx, ny, nz]`.
    Lattice([usize; 3]),
    /// Unstructured points.
    Points,
}

/// A body of a built scene: its name, where its particles are, how they are arranged.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name from the scene file.
    pub name: String,
    /// Its particles' indices in the simulation.
    pub range: Range<usize>,
    /// Arrangement.
    pub topology: Topology,
    /// Surface triangles as simulation particle indices (empty for chains and points).
    pub triangles: Vec<[u32; 3]>,
    /// Contact thickness of the surface, metres (zero: bare per-particle contacts, docs/physics.md §3.3).
    pub thickness: f64,
}

/// The geometry of a collider, for drawing.
#[derive(Clone, Debug, PartialEq)]
pub enum ColliderGeometry {
    /// The ground plane at this height.
    Ground(f64),
    /// An inclined plane `[a, b, c, d]`.
    Plane([f64; 4]),
    /// The free box interior.
    Box(BoxInterior),
    /// An analytic cylinder tabletop.
    Cylinder(Cylinder),
    /// A triangle mesh, as world-space triangles.
    Mesh(Vec<[Vec3; 3]>),
}

/// A scene ready to run: the simulation at step 0 and what is needed to run and draw it.
#[derive(Debug)]
pub struct Scene {
    /// The description it was built from.
    pub spec: SceneSpec,
    /// The simulation at step 0.
    pub simulation: Simulation,
    /// Steps in a full run.
    pub steps: u64,
    /// A frame every this many steps.
    pub every: u64,
    /// The bodies.
    pub bodies: Vec<Body>,
    /// Collider geometry, in the order of the scene file.
    pub colliders: Vec<ColliderGeometry>,
}

/// What replaces a scene's table: every mesh or cylinder collider.
#[derive(Clone, Debug, PartialEq)]
pub enum TableOverride {
    /// The analytic cylinder of the built-in round table
    /// ([`crate::builtin::round_table_cylinder`]).
    Cylinder,
    /// A triangle mesh: `builtin:NAME` or an OBJ path, resolved like the scene's own mesh
    /// paths (against the scene file's folder: callers with a path from elsewhere, such as
    /// a command line, pass it absolute).
    Mesh(String),
}

impl std::str::FromStr for TableOverride {
    type Err = std::convert::Infallible;

    /// `cylinder`, or anything else as a mesh path.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s {
            "cylinder" => Self::Cylinder,
            path => Self::Mesh(path.to_string()),
        })
    }
}

/// Overrides applied on top of a scene file, as from the command line. Errors name the
/// scene's own keys (`simulation.dt`, `table`); a caller with other names for them (the
/// command line's `--dt`) says so itself.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// Replace the integrator.
    pub integrator: Option<hooke_core::Integrator>,
    /// Replace the step size (seconds).
    pub dt: Option<f64>,
    /// Replace the run length with this many steps.
    pub steps: Option<u64>,
    /// Replace the run length with this duration (seconds).
    pub duration: Option<f64>,
    /// Replace the frame cadence.
    pub every: Option<u64>,
    /// Replace every mesh or cylinder collider.
    pub table: Option<TableOverride>,
}

impl Overrides {
    /// Applies the overrides to a scene description.
    pub fn apply(&self, spec: &mut SceneSpec) -> Result<(), BuildError> {
        let sim = &mut spec.simulation;
        if let Some(i) = self.integrator {
            sim.integrator = IntegratorName(i);
        }
        if let Some(dt) = self.dt {
            sim.dt = Positive::try_from(dt).map_err(|m| invalid("simulation.dt", m))?;
        }
        if let Some(steps) = self.steps {
            sim.steps = Some(steps);
            sim.duration = None;
        }
        if let Some(t) = self.duration {
            sim.duration =
                Some(Positive::try_from(t).map_err(|m| invalid("simulation.duration", m))?);
            sim.steps = None;
        }
        if let Some(every) = self.every {
            sim.every = every;
        }
        if let Some(table) = &self.table {
            let mut replaced = false;
            for c in &mut spec.colliders {
                if matches!(
                    c.shape,
                    ColliderShapeSpec::Mesh { .. } | ColliderShapeSpec::Cylinder { .. }
                ) {
                    c.shape = match table {
                        TableOverride::Cylinder => crate::builtin::round_table_cylinder(),
                        TableOverride::Mesh(path) => ColliderShapeSpec::Mesh {
                            path: path.clone(),
                            translate: [Finite(0.0); 3],
                            rotate: [Finite(0.0); 3],
                            scale: [Positive(1.0); 3],
                        },
                    };
                    replaced = true;
                }
            }
            if !replaced {
                return Err(invalid(
                    "table",
                    format!(
                        "scene '{}' has no table (mesh or cylinder collider) to replace",
                        spec.name
                    ),
                ));
            }
        }
        Ok(())
    }
}

fn vec3(v: &[Finite; 3]) -> Vec3 {
    Vec3::new(v[0].0, v[1].0, v[2].0)
}

fn rotation(degrees: &[Finite; 3]) -> Rotation3<f64> {
    let r = vec3(degrees).map(f64::to_radians);
    Rotation3::from_euler_angles(r.x, r.y, r.z)
}

impl SceneSpec {
    /// Steps in a full run, from `steps` or `duration / dt` rounded to the nearest step.
    pub fn total_steps(&self) -> Result<u64, BuildError> {
        let sim = &self.simulation;
        match (sim.steps, sim.duration) {
            (Some(_), Some(_)) => Err(invalid(
                "simulation",
                "give `steps` or `duration`, not both",
            )),
            (None, None) => Err(invalid(
                "simulation",
                "expected `steps` or `duration` (the length of the run)",
            )),
            (Some(0), None) => Err(invalid("simulation.steps", "expected at least 1 step")),
            (Some(n), None) if n > MAX_STEPS => Err(invalid(
                "simulation.steps",
                format!("expected at most {MAX_STEPS} steps, found {n}"),
            )),
            (Some(n), None) => Ok(n),
            (None, Some(t)) => {
                let n = (t.0 / sim.dt.0).round();
                if !(1.0..=MAX_STEPS as f64).contains(&n) {
                    Err(invalid(
                        "simulation.duration",
                        format!(
                            "{} s at dt = {} s is {}; expected 1 to {MAX_STEPS} steps",
                            Num(t.0),
                            Num(sim.dt.0),
                            if n < 1.0 {
                                "less than one step".to_string()
                            } else {
                                format!("{n:.3e} steps")
                            }
                        ),
                    ))
                } else {
                    Ok(n as u64)
                }
            }
        }
    }

    /// Builds the scene. Relative mesh paths are resolved against `base` (the scene file's
    /// folder).
    pub fn build(&self, base: &Path) -> Result<Scene, BuildError> {
        let steps = self.total_steps()?;
        let every = self.simulation.every;
        if every == 0 {
            return Err(invalid(
                "simulation.every",
                "expected a frame cadence of at least 1 step",
            ));
        }
        let mut particles = Particles::default();
        let mut springs = Vec::new();
        let mut bodies = Vec::new();
        let mut surfaces = Vec::new();
        for (b, body) in self.bodies.iter().enumerate() {
            let key = format!("body[{b}] '{}'", body.name);
            // Exports and messages name bodies: two of one name could not be told apart.
            if let Some(first) = self.bodies[..b].iter().position(|o| o.name == body.name) {
                return Err(invalid(
                    format!("{key}.name"),
                    format!(
                        "body[{first}] already has the name '{}'; names must differ",
                        body.name
                    ),
                ));
            }
            let start = particles.len();
            // Checked before anything is allocated.
            if particle_count(&body.shape)
                .and_then(|n| n.checked_add(start))
                .is_none_or(|n| n > MAX_PARTICLES)
            {
                return Err(invalid(
                    format!("{key}.shape"),
                    format!("the scene would have more than {MAX_PARTICLES} particles"),
                ));
            }
            let built = build_body(body, &key, particles.len())?;
            let r = rotation(&body.rotate);
            let o = vec3(&body.origin);
            let n = built.local.len();
            if let Some(ps) = &body.positions
                && ps.len() != n
            {
                return Err(invalid(
                    format!("{key}.positions"),
                    format!(
                        "expected {n} positions (one per particle), found {}",
                        ps.len()
                    ),
                ));
            }
            if let Some(vs) = &body.velocities
                && vs.len() != n
            {
                return Err(invalid(
                    format!("{key}.velocities"),
                    format!(
                        "expected {n} velocities (one per particle), found {}",
                        vs.len()
                    ),
                ));
            }
            for (p, local) in built.local.iter().enumerate() {
                let x = match &body.positions {
                    Some(ps) => vec3(&ps[p]),
                    None => o + r * local,
                };
                let v = body
                    .velocities
                    .as_ref()
                    .map_or(vec3(&body.velocity), |vs| vec3(&vs[p]));
                if x.amax().is_nan() || x.amax() > SANE_BOUND {
                    let what = if body.positions.is_some() {
                        "positions"
                    } else {
                        "origin"
                    };
                    return Err(invalid(
                        format!("{key}.{what}"),
                        format!(
                            "particle {p} would start at ({}, {}, {}), beyond {} m of the origin \
                             (the extent of a simulated world)",
                            Num(x.x),
                            Num(x.y),
                            Num(x.z),
                            Num(SANE_BOUND)
                        ),
                    ));
                }
                particles.push(x, v, body.mass.0);
            }
            for (k, &pin) in body.pins.iter().enumerate() {
                if pin >= n {
                    return Err(invalid(
                        format!("{key}.pins[{k}]"),
                        format!(
                            "particle {pin} does not exist; the body has {n} (0 to {})",
                            n - 1
                        ),
                    ));
                }
                particles.pin(start + pin);
            }
            springs.extend(built.springs);
            let triangles = crate::surface::triangles(built.topology, start);
            let surface = body_surface(body, &key, &built.local, start..start + n, triangles)?;
            bodies.push(Body {
                name: body.name.clone(),
                range: start..start + n,
                topology: built.topology,
                triangles: surface.triangles.clone(),
                thickness: surface.thickness,
            });
            if surface.is_active() {
                surfaces.push(surface);
            }
        }
        let centroid = if particles.is_empty() {
            Vec3::zeros()
        } else {
            particles.centroid()
        };
        let mut slots = Vec::new();
        let mut geometry = Vec::new();
        for (c, spec) in self.colliders.iter().enumerate() {
            let key = format!("collider[{c}]");
            // Penalty forces need an inside: a mesh under one must be a closed solid. The
            // velocity responses also catch crossings, so open sheets work with them.
            let solid = matches!(spec.response, ResponseSpec::Penalty { .. });
            let (shape, geo) = build_collider(&spec.shape, &key, base, &centroid, solid)?;
            let response = match spec.response {
                ResponseSpec::Penalty { kc, dc } => Response::Penalty { kc: kc.0, dc: dc.0 },
                ResponseSpec::Restitution { cr, friction } => Response::Restitution {
                    cr: cr.0,
                    friction: friction.0,
                },
                ResponseSpec::Stick => Response::Stick,
            };
            slots.push(ColliderSlot { shape, response });
            geometry.push(geo);
        }
        let field = match &self.force_field {
            None => None,
            Some(f) if f.resolution == 0 => None,
            Some(f) => {
                let values = f.values.iter().map(vec3).collect::<Vec<_>>();
                let found = values.len();
                let field = ForceField::new(f.resolution, values).ok_or_else(|| {
                    invalid(
                        "force_field.values",
                        format!(
                            "expected resolution³ = {} vectors, found {found}",
                            f.resolution.saturating_pow(3)
                        ),
                    )
                })?;
                // A field that is zero everywhere (as in most of the course's worlds) adds
                // nothing, and sampling it costs a fifth of a jelly's step: leave it out.
                // Forces are the same numbers (at most a -0 becomes +0).
                (!field.is_zero()).then_some(field)
            }
        };
        let model = Model {
            springs,
            gravity: vec3(&self.simulation.gravity),
            drag: self.simulation.drag.0,
            field,
            colliders: slots,
            attachments: Vec::new(),
            surfaces,
        };
        let simulation = Simulation::new(
            particles,
            model,
            self.simulation.integrator.0,
            self.simulation.dt.0,
        );
        Ok(Scene {
            spec: self.clone(),
            simulation,
            steps,
            every,
            bodies,
            colliders: geometry,
        })
    }
}

/// The contact surface of a body: its triangles with the thickness, self-collision and
/// friction its spec gives or the defaults for its shape.
fn body_surface(
    body: &BodySpec,
    key: &str,
    local: &[Vec3],
    particles: Range<usize>,
    triangles: Vec<[u32; 3]>,
) -> Result<Surface, BuildError> {
    let default = match body.shape {
        // A quarter of the spacing at most, so a fine cloth's neighbours never touch.
        ShapeSpec::Grid { spacing, .. } => DEFAULT_CLOTH_THICKNESS.min(0.25 * spacing.0),
        _ => 0.0,
    };
    let thickness = body.thickness.map_or(default, |h| h.0);
    if thickness > 0.0 && triangles.is_empty() {
        return Err(invalid(
            format!("{key}.thickness"),
            "only bodies with a surface (grid, lattice) have a contact thickness; remove it",
        ));
    }
    let self_collision = body.self_collision.unwrap_or(true);
    let surface = Surface {
        particles,
        triangles,
        thickness,
        self_collision,
        friction: body.friction.map_or(DEFAULT_SURFACE_FRICTION, |f| f.0),
    };
    if thickness > 0.0 && self_collision && !surface.triangles.is_empty() {
        // Measured on the rest shape, which is what the springs keep.
        let start = surface.particles.start;
        let rest = |i: u32| local[i as usize - start];
        let shortest = surface
            .edges()
            .iter()
            .map(|&[a, b]| (rest(a) - rest(b)).norm())
            .fold(f64::INFINITY, f64::min);
        if thickness >= 0.5 * shortest {
            return Err(invalid(
                format!("{key}.thickness"),
                format!(
                    "{thickness} m is not under half the surface's shortest edge ({shortest:.4} m): \
                     self-collision would push neighbouring particles apart; \
                     use a thinner surface or self_collision = false"
                ),
            ));
        }
    }
    Ok(surface)
}

struct BuiltBody {
    local: Vec<Vec3>,
    springs: Vec<Spring>,
    topology: Topology,
}

fn build_body(body: &BodySpec, key: &str, offset: usize) -> Result<BuiltBody, BuildError> {
    let (lattice, h, topology) = match &body.shape {
        ShapeSpec::Chain { count, spacing } => (
            Lattice {
                size: [*count, 1, 1],
            },
            spacing.0,
            Topology::Chain,
        ),
        ShapeSpec::Grid { size, spacing } => (
            Lattice {
                size: [size[0], 1, size[1]],
            },
            spacing.0,
            Topology::Grid(*size),
        ),
        ShapeSpec::Lattice { size, spacing } => {
            (Lattice { size: *size }, spacing.0, Topology::Lattice(*size))
        }
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
                springs,
                topology: Topology::Points,
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
                ks: p.ks.0,
                kd: p.kd.0,
                kind,
            }));
        }
    }
    springs.extend(pairs(body, key, &local, offset)?);
    Ok(BuiltBody {
        local,
        springs,
        topology,
    })
}

fn pairs(
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
                .map_or_else(|| (local[p.i] - local[p.j]).norm(), |r| r.0);
            Ok(Spring {
                i: (offset + p.i) as u32,
                j: (offset + p.j) as u32,
                rest,
                ks: p.ks.0,
                kd: p.kd.0,
                kind: SpringKind::Other,
            })
        })
        .collect()
}

/// The size in bytes of the mesh a path names (0 when it cannot be found: the build says why).
pub(crate) fn mesh_file_len(path: &str, base: &Path) -> u64 {
    match path.strip_prefix("builtin:") {
        Some(name) => BUILTIN_MESHES
            .iter()
            .find(|(n, _)| *n == name)
            .map_or(0, |(_, text)| text.len() as u64),
        None => std::fs::metadata(base.join(path)).map_or(0, |m| m.len()),
    }
}

/// Where a mesh path points: a built-in mesh or a file.
fn mesh_text(path: &str, base: &Path) -> Result<(String, PathBuf), MeshError> {
    if let Some(name) = path.strip_prefix("builtin:") {
        return match BUILTIN_MESHES.iter().find(|(n, _)| *n == name) {
            Some((_, text)) => Ok((text.to_string(), PathBuf::from(path))),
            None => Err(MeshError::Io {
                path: PathBuf::from(path),
                source: std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!(
                        "no built-in mesh '{name}'; built-in meshes: {}",
                        BUILTIN_MESHES.map(|m| m.0).join(", ")
                    ),
                ),
            }),
        };
    }
    let full = base.join(path);
    let text = std::fs::read_to_string(&full).map_err(|source| MeshError::Io {
        path: full.clone(),
        source,
    })?;
    Ok((text, full))
}

fn build_collider(
    shape: &ColliderShapeSpec,
    key: &str,
    base: &Path,
    centroid: &Vec3,
    solid: bool,
) -> Result<(Box<dyn Collider>, ColliderGeometry), BuildError> {
    Ok(match shape {
        ColliderShapeSpec::Ground { height } => (
            Box::new(Plane::ground(height.0)),
            ColliderGeometry::Ground(height.0),
        ),
        ColliderShapeSpec::Plane { coefficients } => {
            let c = coefficients.map(|x| x.0);
            let plane = Plane::inclined(c, centroid).ok_or_else(|| {
                invalid(
                    format!("{key}.shape.coefficients"),
                    "expected a plane: (a, b, c) must not be all zero",
                )
            })?;
            (Box::new(plane), ColliderGeometry::Plane(c))
        }
        ColliderShapeSpec::Box { min, max } => {
            let b = BoxInterior {
                min: vec3(min),
                max: vec3(max),
            };
            if (0..3).any(|d| b.min[d] >= b.max[d]) {
                return Err(invalid(
                    format!("{key}.shape"),
                    "expected min < max on every axis",
                ));
            }
            (Box::new(b), ColliderGeometry::Box(b))
        }
        ColliderShapeSpec::Cylinder {
            center,
            radius,
            thickness,
        } => {
            let c = Cylinder {
                center: vec3(center),
                radius: radius.0,
                thickness: thickness.0,
            };
            (Box::new(c), ColliderGeometry::Cylinder(c))
        }
        ColliderShapeSpec::Mesh {
            path,
            translate,
            rotate,
            scale,
        } => {
            let placement = Placement {
                translate: vec3(translate),
                rotate: vec3(rotate),
                scale: Vec3::new(scale[0].0, scale[1].0, scale[2].0),
            };
            let mesh = || -> Result<TriMeshCollider, MeshError> {
                let (text, full) = mesh_text(path, base)?;
                let parts = hooke_collide::parse_obj(&text, &full, &placement)?;
                TriMeshCollider::new(format!("mesh {path}"), parts, &full, solid)
            };
            let mesh = mesh().map_err(|source| BuildError::Mesh {
                key: format!("{key}.shape.path"),
                source,
            })?;
            let tris = mesh.triangles();
            (Box::new(mesh), ColliderGeometry::Mesh(tris))
        }
    })
}
