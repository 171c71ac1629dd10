//! The five course worlds against the reference trajectories the validation suite locks
//! (`tests/snapshots/`, eight corners at steps 100, 500 and 1000, six significant digits):
//! the largest corner difference per world and integrator. With the world's own integrator
//! it must be within the references' rounding; the others show how far each scheme drifts
//! from it at the world's step.

use super::references::{References, WORLDS};
use crate::Result;
use hooke_core::Integrator;
use hooke_scene::Overrides;
use serde::Serialize;

/// The references' rounding: six significant digits of coordinates below 10 m.
pub(crate) const ROUNDING: f64 = 5e-5;

/// One world with one integrator.
#[derive(Serialize)]
pub(crate) struct WorldRun {
    pub(crate) world: String,
    pub(crate) integrator: String,
    /// The world's own integrator (the one its reference was made with).
    pub(crate) own: bool,
    /// The largest corner difference from the reference, m; `None`: diverged.
    pub(crate) max_difference: Option<f64>,
}

impl WorldRun {
    /// Whether the run stayed within the reference's rounding.
    pub(crate) fn matches_reference(&self) -> bool {
        self.max_difference.is_some_and(|d| d <= ROUNDING)
    }
}

/// `(step, particle, position)` of a reference.
fn reference(text: &str) -> Vec<(u64, usize, [f64; 3])> {
    let mut out = Vec::new();
    let mut step = 0;
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("step ") {
            step = rest
                .split_whitespace()
                .next()
                .and_then(|s| s.parse().ok())
                .unwrap_or(0);
        } else if let Some(rest) = line.trim().strip_prefix('p')
            && let Some((index, xyz)) = rest.split_once(": ")
            && let Ok(p) = index.parse::<usize>()
        {
            let v: Vec<f64> = xyz
                .split_whitespace()
                .filter_map(|s| s.parse().ok())
                .collect();
            if v.len() == 3 && step > 0 {
                out.push((step, p, [v[0], v[1], v[2]]));
            }
        }
    }
    out
}

fn run(
    name: &str,
    text: &str,
    reference: &[(u64, usize, [f64; 3])],
    i: Integrator,
    own: bool,
) -> Result<WorldRun> {
    let dir = std::env::temp_dir();
    let world = hooke_scene::world::parse_world(text, &dir.join(format!("{name}.w")))?;
    let mut spec = world.to_scene(name)?;
    Overrides {
        integrator: Some(i),
        ..Overrides::default()
    }
    .apply(&mut spec)?;
    let mut scene = spec.build(&dir)?;
    let mut worst: f64 = 0.0;
    let mut at = 0;
    for &(step, p, x) in reference {
        while at < step {
            crate::interrupt::check(&scene.simulation)?;
            if scene.simulation.step().is_err() {
                return Ok(WorldRun {
                    world: name.into(),
                    integrator: i.to_string(),
                    own,
                    max_difference: None,
                });
            }
            at += 1;
        }
        let y = scene.simulation.particles().x[p];
        worst = worst.max((0..3).map(|k| (y[k] - x[k]).abs()).fold(0.0, f64::max));
    }
    Ok(WorldRun {
        world: name.into(),
        integrator: i.to_string(),
        own,
        max_difference: Some(worst),
    })
}

/// Every world with every integrator (the world's own only, with `quick`).
pub(crate) fn runs(
    quick: bool,
    references: &References,
    tick: &mut dyn FnMut(),
) -> Result<Vec<WorldRun>> {
    let mut out = Vec::new();
    for name in WORLDS {
        let reference = reference(&references.snapshot(name)?);
        let text = references.world(name)?;
        let own = hooke_scene::world::parse_world(&text, std::path::Path::new(name))?.integrator;
        for i in Integrator::ALL {
            if quick && i != own {
                continue;
            }
            out.push(run(name, &text, &reference, i, i == own)?);
        }
        tick();
    }
    Ok(out)
}
