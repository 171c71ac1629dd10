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
