//! From a scene description to a ready-to-step simulation.

use crate::colliders::{build_collider, response};
use crate::error::{BuildError, invalid};
use crate::generators::Lattice;
use crate::limits::{
    DT_RANGE, MAX_AIR_DENSITY, MAX_PARTICLES, MAX_PENALTY, MAX_STEPS, MAX_WIND, particle_count,
};
use crate::scene::{Body, ColliderGeometry, Scene, Topology};
use crate::spec::*;
use hooke_core::{AeroSurface, Air, Gust, Num, PinMotion, SANE_BOUND, StartInside};
use hooke_core::{
    ColliderSlot, DEFAULT_CLOTH_THICKNESS, DEFAULT_SURFACE_FRICTION, ForceField, Model, Particles,
    Simulation, Spring, SpringKind, Surface, Vec3,
};
use std::ops::Range;
use std::path::{Path, PathBuf};

impl SceneSpec {
    /// Steps in a full run, from `steps` or `duration / dt` rounded to the nearest step.
    pub fn total_steps(&self) -> Result<u64, BuildError> {
        let sim = &self.simulation;
        if !DT_RANGE.contains(&sim.dt.get()) {
            return Err(invalid(
                "simulation.dt",
                format!(
                    "{} s is a step no solver here can represent: its square and inverse \
                     square leave the numbers' range in the stiffness and inertia terms; \
                     expected {:e} to {:e} s",
                    Num(sim.dt.get()),
                    DT_RANGE.start(),
                    DT_RANGE.end()
                ),
            ));
        }
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
                let n = (t.get() / sim.dt.get()).round();
                if !(1.0..=MAX_STEPS as f64).contains(&n) {
                    Err(invalid(
                        "simulation.duration",
                        format!(
                            "{} s at dt = {} s is {}; expected 1 to {MAX_STEPS} steps",
                            Num(t.get()),
                            Num(sim.dt.get()),
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
    /// folder). The steps, in order: the run's length and cadence, the bodies (particles,
    /// springs, surfaces, air triangles), the colliders, the force field, then the model.
    pub fn build(&self, base: &Path) -> Result<Scene, BuildError> {
        let (steps, every) = self.run_length()?;
        let built = self.build_bodies()?;
        let centroid = if built.particles.is_empty() {
            Vec3::zeros()
        } else {
            built.particles.centroid()
        };
        let (colliders, geometry) = self.build_colliders(base, &centroid)?;
        let model = Model {
            springs: built.springs,
            gravity: vec3(&self.simulation.gravity),
            drag: self.simulation.drag.get(),
            field: self.build_field()?,
            colliders,
            attachments: Vec::new(),
            surfaces: built.surfaces,
            air: self.simulation.air.map(|a| Air {
                density: a.density.get(),
                wind: vec3(&a.wind),
                gust: a.gust.map(|g| Gust {
                    amplitude: vec3(&g.amplitude),
                    period: g.period.get(),
                }),
            }),
            aero: built.aero,
            pin_motions: built.pin_motions,
        };
        let mut simulation = Simulation::new(
            built.particles,
            model,
            self.simulation.integrator.0,
            self.simulation.dt.get(),
        );
        let pushed_out = simulation.push_out_start().map_err(|e| {
            let particle = match &e {
                StartInside::Through(i, ..) | StartInside::Stuck(i, ..) => *i,
            };
            let b = built
                .bodies
                .iter()
                .position(|b| b.range.contains(&particle))
                .unwrap_or(0);
            invalid(
                format!("body[{b}] '{}'", built.bodies[b].name),
                e.to_string(),
            )
        })?;
        Ok(Scene {
            spec: self.clone(),
            simulation,
            steps,
            every,
            bodies: built.bodies,
            colliders: geometry,
            pushed_out,
        })
    }

    /// Steps in the run and steps per frame, with the air checked.
    fn run_length(&self) -> Result<(u64, u64), BuildError> {
        let steps = self.total_steps()?;
        let every = self.simulation.every;
        if every == 0 {
            return Err(invalid(
                "simulation.every",
                "expected a frame cadence of at least 1 step",
            ));
        }
        if let Some(air) = &self.simulation.air {
            check_air(air)?;
        }
        Ok((steps, every))
    }

    /// Every body's particles, springs, contact surface and air triangles, in file order.
    fn build_bodies(&self) -> Result<Bodies, BuildError> {
        let mut out = Bodies::default();
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
            self.build_body_into(body, &key, &mut out)?;
        }
        Ok(out)
    }

    /// One body appended to `out`.
    fn build_body_into(
        &self,
        body: &BodySpec,
        key: &str,
        out: &mut Bodies,
    ) -> Result<(), BuildError> {
        let particles = &mut out.particles;
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
        let built = build_body(body, key, particles.len())?;
        let n = built.local.len();
        place_particles(body, key, (&built.local, &built.masses), particles)?;
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
        if let Some(motion) = &body.pin_motion {
            out.pin_motions
                .push(pin_motion(body, motion, key, start, particles)?);
        }
        out.springs.extend(built.springs);
        let triangles = crate::surface::triangles(built.topology, start);
        let surface = body_surface(body, key, &built.local, start..start + n, triangles)?;
        if let Some(a) = body_aero(body, key, &surface.triangles, self.simulation.air)? {
            out.aero.push(a);
        }
        out.bodies.push(Body {
            name: body.name.clone(),
            range: start..start + n,
            topology: built.topology,
            triangles: surface.triangles.clone(),
            thickness: surface.thickness,
        });
        if surface.is_active() {
            out.surfaces.push(surface);
        }
        Ok(())
    }

    /// The colliders in file order, with their geometry for drawing; an inclined plane is
    /// placed relative to the bodies' `centroid`.
    fn build_colliders(
        &self,
        base: &Path,
        centroid: &Vec3,
    ) -> Result<(Vec<ColliderSlot>, Vec<ColliderGeometry>), BuildError> {
        let mut slots = Vec::new();
        let mut geometry = Vec::new();
        for (c, spec) in self.colliders.iter().enumerate() {
            let key = format!("collider[{c}]");
            // Penalty forces need an inside: a mesh under one must be a closed solid. The
            // velocity responses also catch crossings, so open sheets work with them.
            let solid = matches!(spec.response, ResponseSpec::Penalty { .. });
            if let ResponseSpec::Penalty { kc, dc } = spec.response {
                for (name, value, unit) in [("kc", kc.get(), "N/m"), ("dc", dc.get(), "N·s/m")] {
                    if value > MAX_PENALTY {
                        return Err(invalid(
                            format!("{key}.response.{name}"),
                            format!(
                                "{} {unit} is beyond what a step can follow or the energy can \
                                 hold: expected at most {MAX_PENALTY:e} {unit}",
                                Num(value)
                            ),
                        ));
                    }
                }
            }
            let (mut shape, geo) = build_collider(&spec.shape, &key, base, centroid, solid)?;
            if let Some(motion) = &spec.motion {
                shape = crate::colliders::moving(shape, &spec.shape, motion, &key)?;
            }
            slots.push(ColliderSlot {
                shape,
                response: response(&spec.response),
            });
            geometry.push(geo);
        }
        Ok((slots, geometry))
    }

    /// The force field, or `None` when there is none or it is zero everywhere.
    fn build_field(&self) -> Result<Option<ForceField>, BuildError> {
        Ok(match &self.force_field {
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
        })
    }
}

/// What the bodies of a scene add up to.
#[derive(Default)]
struct Bodies {
    particles: Particles,
    springs: Vec<Spring>,
    bodies: Vec<Body>,
    surfaces: Vec<Surface>,
    aero: Vec<AeroSurface>,
    pin_motions: Vec<PinMotion>,
}

/// Pushes a body's particles: at its `positions`, or its local layout rotated and moved to
/// its origin; with its `velocities` or its one velocity. Refuses a count that does not
/// match and a particle beyond the world's extent.
fn place_particles(
    body: &BodySpec,
    key: &str,
    (local, masses): (&[Vec3], &[f64]),
    particles: &mut Particles,
) -> Result<(), BuildError> {
    let r = rotation(&body.rotate);
    let o = vec3(&body.origin);
    let n = local.len();
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
    for (p, local) in local.iter().enumerate() {
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
        particles.push(x, v, masses[p]);
    }
    Ok(())
}

/// Refuses air whose wind (steady plus the gust's largest change) reaches [`MAX_WIND`].
fn check_air(air: &AirSpec) -> Result<(), BuildError> {
    let density = air.density.get();
    if density > MAX_AIR_DENSITY {
        return Err(invalid(
            "simulation.air.density",
            format!(
                "{} kg/m³ is denser than any fluid (water is 1000, mercury 13,534): expected at \
                 most {MAX_AIR_DENSITY:e} kg/m³ (sea-level air is 1.225)",
                Num(density)
            ),
        ));
    }
    let wind = vec3(&air.wind);
    let gust = air.gust.map_or(Vec3::zeros(), |g| vec3(&g.amplitude));
    let fastest = wind.norm() + gust.norm();
    if fastest.is_finite() && fastest < MAX_WIND {
        return Ok(());
    }
    let key = if gust.norm() > wind.norm() {
        "simulation.air.gust.amplitude"
    } else {
        "simulation.air.wind"
    };
    let shown = |v: &Vec3| format!("[{}, {}, {}]", Num(v.x), Num(v.y), Num(v.z));
    Err(invalid(
        key,
        format!(
            "a wind of {} m/s with gusts of {} m/s reaches {} m/s; Hooke's air is \
             incompressible drag, which means nothing at or beyond the speed of sound: expected \
             less than {MAX_WIND} m/s in all",
            shown(&wind),
            shown(&gust),
            if fastest.is_finite() {
                format!("{fastest:.1}")
            } else {
                "far beyond any number".to_string()
            }
        ),
    ))
}

/// The triangles of a body that the air acts on, with its coefficients: none without air.
fn body_aero(
    body: &BodySpec,
    key: &str,
    triangles: &[[u32; 3]],
    air: Option<AirSpec>,
) -> Result<Option<AeroSurface>, BuildError> {
    if body.aero.is_some() && triangles.is_empty() {
        return Err(invalid(
            format!("{key}.aero"),
            "only bodies with a surface (grid, lattice) feel air; remove it",
        ));
    }
    if air.is_none() || triangles.is_empty() {
        return Ok(None);
    }
    let coefficients = body.aero.unwrap_or_default();
    Ok(Some(AeroSurface {
        triangles: triangles.to_vec(),
        drag: coefficients.drag.get(),
        lift: coefficients.lift.get(),
    }))
}

/// The contact thickness a body with a surface gets when its spec gives none: for a grid
/// the cloth default, at most a quarter of the spacing so that a fine cloth's neighbours
/// never touch; none for other shapes.
fn default_thickness(shape: &ShapeSpec) -> f64 {
    match shape {
        ShapeSpec::Grid { spacing, .. } => DEFAULT_CLOTH_THICKNESS.min(0.25 * spacing.get()),
        _ => 0.0,
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
    // A body without triangles (a chain, points, a grid one particle wide) has no surface:
    // its default thickness is none, and contact keys written for it are refused by name.
    let default = if triangles.is_empty() {
        0.0
    } else {
        default_thickness(&body.shape)
    };
    let thickness = body.thickness.map_or(default, |h| h.get());
    if triangles.is_empty() {
        let written = [
            ("thickness", body.thickness.is_some_and(|h| h.get() > 0.0)),
            ("self_collision", body.self_collision.is_some()),
            ("friction", body.friction.is_some()),
        ];
        if let Some((name, _)) = written.iter().find(|(_, w)| *w) {
            return Err(invalid(
                format!("{key}.{name}"),
                "only bodies with a surface (a grid or lattice at least 2 particles wide) take \
                 contact keys; this body has no triangles: remove it",
            ));
        }
    }
    let self_collision = body.self_collision.unwrap_or(true);
    let surface = Surface {
        particles,
        triangles,
        thickness,
        self_collision,
        friction: body.friction.map_or(DEFAULT_SURFACE_FRICTION, |f| f.get()),
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
                    "{} m is not under half the surface's shortest edge ({shortest:.4} m): \
                     self-collision would push neighbouring particles apart; \
                     use a thinner surface or self_collision = false",
                    Num(thickness)
                ),
            ));
        }
    }
    Ok(surface)
}

struct BuiltBody {
    local: Vec<Vec3>,
    /// Per particle, kg.
    masses: Vec<f64>,
    springs: Vec<Spring>,
    topology: Topology,
}

fn build_body(body: &BodySpec, key: &str, offset: usize) -> Result<BuiltBody, BuildError> {
    if let Some(material) = &body.material {
        return material_body(body, material, key, offset);
    }
    let Some(mass) = body.mass else {
        return Err(invalid(
            format!("{key}.mass"),
            "missing: give `mass` (kg per particle) and `springs`, or a `[body.material]`",
        ));
    };
    let mut built = spring_body(body, key, offset)?;
    built.masses = vec![mass.get(); built.local.len()];
    Ok(built)
}

/// A body's keyframed pins (docs/physics.md §1.2): its pinned particles, moved by `motion`.
fn pin_motion(
    body: &BodySpec,
    motion: &crate::spec::MotionSpec,
    key: &str,
    start: usize,
    particles: &Particles,
) -> Result<PinMotion, BuildError> {
    if body.pins.is_empty() {
        return Err(invalid(
            format!("{key}.pin_motion"),
            "it moves the body's pinned particles, and the body has none: give `pins`",
        ));
    }
    let keys = crate::colliders::keyframes(motion, &format!("{key}.pin_motion"))?;
    let mut ids: Vec<u32> = body.pins.iter().map(|&p| (start + p) as u32).collect();
    ids.sort_unstable();
    ids.dedup();
    Ok(PinMotion::new(ids, &particles.x, keys))
}

/// A grid given as a material: its masses and springs derived for its spacing.
fn material_body(
    body: &BodySpec,
    material: &crate::spec::MaterialSpec,
    key: &str,
    offset: usize,
) -> Result<BuiltBody, BuildError> {
    let given: Vec<&str> = [
        ("mass", body.mass.is_some()),
        ("springs", !body.springs.is_empty()),
    ]
    .iter()
    .filter(|(_, on)| *on)
    .map(|(name, _)| *name)
    .collect();
    if !given.is_empty() {
        return Err(invalid(
            format!("{key}.material"),
            format!(
                "a material gives the masses and springs: remove {} (or the material)",
                given
                    .iter()
                    .map(|k| format!("`{k}`"))
                    .collect::<Vec<_>>()
                    .join(" and ")
            ),
        ));
    }
    let ShapeSpec::Grid { size, spacing } = &body.shape else {
        return Err(invalid(
            format!("{key}.material"),
            "a material is for a cloth: the body's shape must be a `grid`",
        ));
    };
    let material = material.resolve(&format!("{key}.material"))?;
    let mut built = spring_body(body, key, offset)?;
    built.masses = material.masses(*size, spacing.get());
    let n = built.local.len();
    let mut held = vec![false; n];
    for &p in body.pins.iter().filter(|&&p| p < n) {
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

impl SceneSpec {
    /// The scene with the contact keys its surfaces default to written out (`thickness`,
    /// `self_collision`, `friction` on every body with triangles), so that an emitted scene
    /// shows them; it builds to the same simulation, bit for bit.
    pub fn with_contact_defaults(&self) -> SceneSpec {
        let mut spec = self.clone();
        for body in &mut spec.bodies {
            // A grid has triangles when it is two particles wide both ways, a lattice when
            // two of its sides are (crate::surface::triangles), without making them.
            let wide = |sides: &[usize]| sides.iter().filter(|&&n| n >= 2).count();
            let surface = match &body.shape {
                ShapeSpec::Grid { size, .. } => wide(size) == 2,
                ShapeSpec::Lattice { size, .. } => wide(size) >= 2,
                _ => false,
            };
            if !surface {
                continue;
            }
            let thickness = default_thickness(&body.shape);
            body.thickness.get_or_insert(NonNegative::of(thickness));
            body.self_collision.get_or_insert(true);
            body.friction
                .get_or_insert(NonNegative::of(DEFAULT_SURFACE_FRICTION));
        }
        spec
    }

    /// The files building the scene reads, each with the key that names it
    /// (`collider[2].shape.path`): its mesh files, resolved against `base` (built-in meshes
    /// are no files). For checking, before a run, that no output replaces one.
    pub fn input_files(&self, base: &Path) -> Vec<(String, PathBuf)> {
        self.colliders
            .iter()
            .enumerate()
            .filter_map(|(c, collider)| match &collider.shape {
                ColliderShapeSpec::Mesh { path, .. } if !path.starts_with("builtin:") => {
                    Some((format!("collider[{c}].shape.path"), base.join(path)))
                }
                _ => None,
            })
            .collect()
    }
}
