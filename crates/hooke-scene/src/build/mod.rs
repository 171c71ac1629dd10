//! From a scene description to a ready-to-step simulation: the run's length and the
//! order of building here, the bodies in [`bodies`], the colliders and the force field in
//! [`world`].

mod bodies;
mod world;

use crate::air::check_air;
use crate::error::{BuildError, invalid};
use crate::limits::MAX_STEPS;
use crate::scene::Scene;
use crate::spec::*;
use hooke_core::{Air, Gust, Num, StartInside};
use hooke_core::{Model, Simulation, Vec3};
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
        let built = self.build_bodies(base)?;
        let centroid = if built.particles.is_empty() {
            Vec3::zeros()
        } else {
            built.particles.centroid()
        };
        let (colliders, geometry, animations) = self.build_colliders(base, &centroid)?;
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
            animations,
            pushed_out,
            build_warnings: built.warnings,
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
}
