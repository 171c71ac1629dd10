//! The largest scene and run accepted: beyond these a typo, not a wish, is the likely
//! cause, and memory or patience would run out before anything useful happened.

use crate::spec::ShapeSpec;

/// Most particles a scene may have (2048²): beyond this a typo (an extra zero in a size)
/// would exhaust memory before anything useful happened. A lattice this large carries about
/// 13 springs per particle, some 3 GB with the solver's buffers.
pub const MAX_PARTICLES: usize = 1 << 22;

/// Most steps a run may take: a billion steps is half an hour of the 12-bead chain and days
/// of the cloth on the table; more is a mistake in `steps`, `duration` or `dt`.
pub const MAX_STEPS: u64 = 1_000_000_000;

/// Particles a shape will have, or `None` when the count overflows.
pub(crate) fn particle_count(shape: &ShapeSpec) -> Option<usize> {
    match shape {
        ShapeSpec::Chain { count, .. } => Some(*count),
        ShapeSpec::Grid { size, .. } => size[0].checked_mul(size[1]),
        ShapeSpec::Lattice { size, .. } => size[0].checked_mul(size[1])?.checked_mul(size[2]),
        ShapeSpec::Points { positions } => Some(positions.len()),
        // Counted as the file is read.
        ShapeSpec::Mesh { .. } | ShapeSpec::Solid { .. } => Some(0),
    }
}

/// The fastest wind a scene may blow, m/s: the speed of sound in air at 20 °C. The air
/// model is incompressible pressure drag, which means nothing at or beyond it.
pub const MAX_WIND: f64 = 343.0;

/// The densest air a scene may have, kg/m³: denser than any liquid at hand (mercury is
/// 13,534). Beyond it a typo is the likely cause, and `½ ρ |u|²` soon leaves what the
/// solver's step sizes can follow.
pub const MAX_AIR_DENSITY: f64 = 2.0e4;

/// The stiffest penalty collider, N/m, and its strongest damping, N·s/m: a gram-weight
/// particle on 1e12 N/m rings at 3e7 rad/s, which asks steps under 1e-7 s, and past it the
/// penalty energy of a deep contact leaves the range of the numbers.
pub const MAX_PENALTY: f64 = 1.0e12;

/// The range of step sizes a scene may take, seconds (the core's
/// [`hooke_core::integrator::DT_RANGE`], where the reason is given).
pub const DT_RANGE: std::ops::RangeInclusive<f64> = hooke_core::integrator::DT_RANGE;

/// Refuses a step outside [`DT_RANGE`], naming `simulation.dt`.
pub(crate) fn check_dt(dt: f64) -> Result<(), crate::BuildError> {
    if DT_RANGE.contains(&dt) {
        return Ok(());
    }
    Err(crate::error::invalid(
        "simulation.dt",
        format!(
            "{} s is a step no solver here can represent: its square and inverse square leave \
             the numbers' range in the stiffness and inertia terms; expected {:e} to {:e} s",
            hooke_core::Num(dt),
            DT_RANGE.start(),
            DT_RANGE.end()
        ),
    ))
}
