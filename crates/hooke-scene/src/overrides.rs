//! Overrides applied on top of a scene description (integrator, step size, run length,
//! frame cadence, the table), keyed by the scene's own names: callers with names of their
//! own, such as the command line's flags, map them.

use crate::BuildError;
use crate::error::invalid;
use crate::spec::*;

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
    /// Replace the step size (seconds). Without [`Overrides::every`], the frame cadence is
    /// scaled to keep the scene's frame interval in time (at least a frame per step).
    pub dt: Option<f64>,
    /// Replace the run length with this many steps.
    pub steps: Option<u64>,
    /// Replace the run length with this duration (seconds).
    pub duration: Option<f64>,
    /// Replace the frame cadence.
    pub every: Option<u64>,
    /// Replace every mesh or cylinder collider.
    pub table: Option<TableOverride>,
    /// Replace block descent's stopping tolerance (m/s).
    pub tolerance: Option<f64>,
    /// Replace block descent's iteration budget per step.
    pub iterations: Option<u64>,
}

impl Overrides {
    /// Applies the overrides to a scene description.
    pub fn apply(&self, spec: &mut SceneSpec) -> Result<(), BuildError> {
        let sim = &mut spec.simulation;
        if let Some(i) = self.integrator {
            sim.integrator = IntegratorName(i);
        }
        if let Some(dt) = self.dt {
            let was = sim.dt.get();
            sim.dt = Positive::try_from(dt).map_err(|m| invalid("simulation.dt", m))?;
            crate::limits::check_dt(dt)?;
            // A new step keeps the scene's frame interval in time, unless the frames are
            // given too: 40 steps of 2.5e-4 s are one step of 1/60 s, not 40.
            if self.every.is_none() {
                let every = (sim.every as f64 * was / dt).round();
                sim.every = if every.is_finite() && every >= 1.0 {
                    (every as u64).min(crate::limits::MAX_STEPS)
                } else {
                    1
                };
            }
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
        if let Some(t) = self.tolerance {
            sim.tolerance =
                Some(Positive::try_from(t).map_err(|m| invalid("simulation.tolerance", m))?);
        }
        if let Some(n) = self.iterations {
            sim.iterations = Some(n);
        }
        if let Some(table) = &self.table {
            let mut replaced = false;
            // A collider that moves by keys (a puck swept through a cloth) is no table: put
            // in its place a table would keep its keys but not its shape or its path's sense.
            if let Some((k, _)) = spec.colliders.iter().enumerate().find(|(_, c)| {
                c.motion.is_some()
                    && matches!(
                        c.shape,
                        ColliderShapeSpec::Mesh { .. } | ColliderShapeSpec::Cylinder { .. }
                    )
            }) {
                return Err(invalid(
                    "table",
                    format!(
                        "collider[{k}] moves by keys (it is no still table), and a \
                         table swapped in would not take its shape, place or path; write the \
                         scene out (hooke scene {}) and change the collider there",
                        spec.name
                    ),
                ));
            }
            for c in &mut spec.colliders {
                if matches!(
                    c.shape,
                    ColliderShapeSpec::Mesh { .. } | ColliderShapeSpec::Cylinder { .. }
                ) {
                    c.shape = match table {
                        TableOverride::Cylinder => crate::builtin::round_table_cylinder(),
                        TableOverride::Mesh(path) => ColliderShapeSpec::Mesh {
                            path: path.clone(),
                            translate: [Finite::of(0.0); 3],
                            rotate: [Finite::of(0.0); 3],
                            scale: [Positive::of(1.0); 3],
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
