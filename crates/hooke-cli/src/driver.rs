//! The run loop: stepping a scene frame by frame, answering Ctrl-C within a step and
//! showing progress on long runs.

use crate::interrupt::{self, Interrupted};
use anyhow::Result;
use hooke_scene::Scene;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

/// Runs shorter than this many steps show no progress bar.
const PROGRESS_FROM: u64 = 10_000;

/// A progress bar on stderr for `steps` steps of the scene, hidden when stderr is not a
/// terminal or the run is short.
fn progress(scene: &Scene, steps: u64) -> ProgressBar {
    if !std::io::stderr().is_terminal() || steps < PROGRESS_FROM {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(steps);
    bar.set_style(
        ProgressStyle::with_template(
            "{prefix} [{bar:40}] {pos}/{len} steps, {elapsed} elapsed, eta {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar.set_prefix(scene.spec.name.clone());
    bar
}

/// The whole number of the scene's steps nearest to `seconds` of simulated time (what
/// `render --at`, the demo's stills and its animation's frame interval take), saturating
/// for times no run reaches.
///
/// ```
/// let scene = hooke_cli::source::build("chain", &Default::default()).unwrap();
/// let dt = scene.simulation.dt();
/// assert_eq!(hooke_cli::driver::steps_for(&scene, 10.4 * dt), 10);
/// assert_eq!(hooke_cli::driver::steps_for(&scene, 1e300), u64::MAX);
/// ```
pub fn steps_for(scene: &Scene, seconds: f64) -> u64 {
    // `as` saturates: negative and NaN give 0, beyond range u64::MAX.
    (seconds / scene.simulation.dt()).round() as u64
}

/// Steps `n` times, one at a time so that an interrupt is answered within a step.
fn steps(scene: &mut Scene, n: u64, bar: &ProgressBar) -> Result<()> {
    for k in 0..n {
        if interrupt::requested() {
            let sim = &scene.simulation;
            return Err(Interrupted {
                step: sim.steps(),
                time: sim.time(),
            }
            .into());
        }
        scene.simulation.step()?;
        if k % 1024 == 1023 {
            bar.set_position(scene.simulation.steps());
        }
    }
    Ok(())
}

/// Steps `scene` to its end, calling `on_frame(frame, scene)` at frame 0 and after every
/// `scene.every` steps. A divergence comes back as an error holding a
/// [`hooke_core::Divergence`], an interrupt as one holding an [`Interrupted`].
pub fn drive(scene: &mut Scene, mut on_frame: impl FnMut(u64, &Scene) -> Result<()>) -> Result<()> {
    let (total, every) = (scene.steps, scene.every);
    let bar = progress(scene, total);
    on_frame(0, scene)?;
    for frame in 1..=total / every {
        steps(scene, every, &bar)?;
        on_frame(frame, scene)?;
    }
    // Steps past the last full frame are still run: the run's length is what was asked for.
    steps(scene, total % every, &bar)?;
    bar.finish_and_clear();
    Ok(())
}

/// Steps `scene` `n` times without frames, interruptible, with progress on long runs.
pub fn advance(scene: &mut Scene, n: u64) -> Result<()> {
    let bar = progress(scene, n);
    steps(scene, n, &bar)?;
    bar.finish_and_clear();
    Ok(())
}
