//! From a scene description to a ready-to-step simulation.

use crate::air::{body_aero, check_air};
use crate::body::{build_body, pin_motion};
use crate::colliders::{build_collider, response};
use crate::contact_surface::body_surface;
use crate::error::{BuildError, invalid};
use crate::limits::{MAX_PARTICLES, MAX_PENALTY, MAX_STEPS, particle_count};
use crate::scene::{Body, ColliderGeometry, Scene};
use crate::spec::*;
use hooke_core::{AeroSurface, Air, Gust, Num, PinMotion, SANE_BOUND, StartInside};
use hooke_core::{ColliderSlot, ForceField, Model, Particles, Simulation, Spring, Surface, Vec3};
use std::path::Path;

impl SceneSpec {
    /// Steps in a full run, from `steps` or `duration / dt` rounded to the nearest step.
    pub fn total_steps(&self) -> Result<u64, BuildError> {
        let sim = &self.simulation;
        crate::limits::check_dt(sim.dt.get())?;
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
        crate::ranges::check_ranges(self)?;
        self.check_drag()?;
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
            mass_drag: self.simulation.mass_drag.get(),
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
        let sim = &self.simulation;
        if sim.tolerance.is_some() || sim.iterations.is_some() {
            let default = hooke_core::StopRule::VBD;
            simulation.set_stop_rule(hooke_core::StopRule {
                tolerance: sim.tolerance.map_or(default.tolerance, |t| t.get()),
                iterations: sim.iterations.map_or(default.iterations, |n| n as usize),
            });
        }
        let pushed_out = simulation.push_out_start().map_err(|e| {
            let particle = match &e {
                StartInside::Through(i, ..)
                | StartInside::Deformed(i, ..)
                | StartInside::Stuck(i, ..) => *i,
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

    /// Refuses `[simulation] drag` with a body given as a material: a drag per particle
    /// changes such a body with its resolution, which a material promises not to do.
    fn check_drag(&self) -> Result<(), BuildError> {
        let drag = self.simulation.drag.get();
        let Some((b, body)) = self
            .bodies
            .iter()
            .enumerate()
            .find(|(_, b)| b.material.is_some())
        else {
            return Ok(());
        };
        if drag == 0.0 {
            return Ok(());
        }
        // The mass drag that gives this body's particles, on average, the same drag.
        let particles = crate::limits::particle_count(&body.shape)
            .unwrap_or(1)
            .max(1) as f64;
        let mass = body
            .material
            .as_ref()
            .and_then(|m| m.resolve(&format!("body[{b}].material")).ok())
            .zip(match body.shape {
                ShapeSpec::Grid { size, spacing } => Some(
                    (size[0].max(2) - 1) as f64
                        * (size[1].max(2) - 1) as f64
                        * spacing.get().powi(2),
                ),
                _ => None,
            })
            .map(|(m, area)| m.density * area / particles);
        let advice = mass.map_or(String::new(), |m| {
            format!(
                " (`mass_drag = {}` gives this resolution's particles the same drag on average)",
                hooke_core::Approx(drag / m)
            )
        });
        Err(invalid(
            "simulation.drag",
            format!(
                "{} N·s/m acts on every particle, so body[{b}] '{}', given as a material, would \
                 feel more drag the finer its grid; give `mass_drag` in N·s/m per kg (1/s) \
                 instead{advice}, or air (`[simulation] air`), whose drag is per area",
                Num(drag),
                body.name
            ),
        ))
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
