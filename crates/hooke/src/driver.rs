//! The run loop: stepping a scene frame by frame, answering Ctrl-C within a step and
//! showing progress on long runs.

use crate::error::{Result, bail_input};
use crate::interrupt;
use crate::progress::{Hidden, Progress, reporter};
use hooke_core::Num;
use hooke_scene::Scene;
use std::time::{Duration, Instant};

/// The progress of `steps` steps of the scene, shown by the installed reporter (which
/// decides when a run is long enough to show).
fn progress(scene: &Scene, steps: u64) -> Box<dyn Progress> {
    if steps == 0 {
        return Box::new(Hidden);
    }
    reporter().run(&scene.spec.name, steps)
}

/// Says, through the installed reporter, the notices of the steps just taken (see
/// [`hooke_core::Notice`]), with the body and the collider named.
fn say_notices(scene: &mut Scene) {
    for n in scene.simulation.take_notices() {
        reporter().warn(&describe(scene, &n));
    }
}

/// Says, at a run's end, how many steps each notice's promise was broken in, when more than
/// the first.
fn tally_notices(scene: &Scene) {
    use hooke_core::Cause;
    for (n, steps) in scene.simulation.notice_tally() {
        if *steps > 1 {
            let why = match n.cause {
                Cause::LargeStep { integrator, .. } | Cause::Layers { integrator, .. } => {
                    format!("{integrator}'s steps moved it farther than its contacts can follow")
                }
                Cause::Pinned => "a pinned particle lay in the collider's path".to_string(),
                Cause::Squeezed { .. } => {
                    "the collider squeezed it faster than the parts of a step could follow"
                        .to_string()
                }
                Cause::Crease { .. } => {
                    "it folded tighter than the pairs self-contact skips".to_string()
                }
            };
            reporter().warn(&format!(
                "a surface of body {} ended {steps} steps in all through {}, the first at step \
                 {}: {why}",
                body_of(scene, n.particle),
                through(scene, n.through),
                n.step
            ));
        }
    }
}

/// Says, at a run's end, how many of its steps the large-step integrator ended at its
/// iteration budget before its stopping rule was met, and the first of them: a result that
/// may be short of what was asked says so (docs/physics.md §4.1, "Stopping rule and
/// accuracy").
fn tally_unsolved(scene: &Scene) {
    let sim = &scene.simulation;
    let (integrator, steps) = (sim.integrator(), sim.steps());
    let unsolved = sim.unsolved();
    let Some(first) = unsolved.first else {
        return;
    };
    let what = if integrator == hooke_core::Integrator::Implicit {
        "with its conjugate gradients at their iteration cap, above their tolerance".to_string()
    } else {
        let rule = sim.workspace().stop_rule_of(integrator);
        format!(
            "at its budget of {} iteration{} before its tolerance of {} m/s",
            rule.iterations,
            if rule.iterations == 1 { "" } else { "s" },
            hooke_core::Approx(rule.tolerance)
        )
    };
    let fix = if integrator.solves_contacts() {
        "; `--iterations` raises the budget, and `hooke bench scene --residual` measures what \
         is left"
    } else {
        ""
    };
    reporter().note(&format!(
        "{integrator} ended {} of {steps} step{} {what}, the first at step {first} \
         (t = {} s): those steps stopped short of their solution (docs/physics.md §4.1, \
         \"Stopping rule and accuracy\"){fix}",
        unsolved.steps,
        if steps == 1 { "" } else { "s" },
        // A step's end time as `Simulation::time` gives it.
        hooke_core::Approx(first as f64 * sim.dt()),
    ));
}

/// What a notice's surface passed through, as said.
fn through(scene: &Scene, through: hooke_core::Through) -> String {
    match through {
        hooke_core::Through::Collider(k) => format!(
            "collider[{k}] ({})",
            scene.simulation.model().colliders[k].shape.name()
        ),
        hooke_core::Through::Itself(_) => "itself".to_string(),
        hooke_core::Through::Surfaces(_, k) => format!(
            "the surface of body {}",
            body_of(scene, scene.simulation.model().surfaces[k].particles.start)
        ),
    }
}

/// `'name'` of the body holding `particle`.
fn body_of(scene: &Scene, particle: usize) -> String {
    scene
        .bodies
        .iter()
        .find(|b| b.range.contains(&particle))
        .map_or_else(
            || format!("of particle {particle}"),
            |b| format!("'{}'", b.name),
        )
}

/// One notice as a sentence: when, which body through which collider (or itself), and why.
pub fn describe(scene: &Scene, n: &hooke_core::Notice) -> String {
    let promise = match (n.through, n.cause) {
        (_, hooke_core::Cause::Crease { .. }) => "which self-contact does not keep out there",
        (_, hooke_core::Cause::Layers { .. }) => {
            "which contacts after so large a step do not keep out"
        }
        _ => "which the run promised not to let happen",
    };
    format!(
        "step {} (t = {} s): a surface of body {} (particle {}) ended the step through {}, \
         {promise}: {}",
        n.step,
        hooke_core::Approx(n.time),
        body_of(scene, n.particle),
        n.particle,
        through(scene, n.through),
        n.cause
    )
}

/// The whole number of the scene's steps nearest to `seconds` of simulated time (what
/// `render --at`, the demo's stills and its animation's frame interval take), saturating
/// for times no run reaches.
///
/// ```
/// let scene = hooke::source::build("chain", &Default::default()).unwrap();
/// let dt = scene.simulation.dt();
/// assert_eq!(hooke::driver::steps_for(&scene, 10.4 * dt), 10);
/// assert_eq!(hooke::driver::steps_for(&scene, 1e300), u64::MAX);
/// ```
pub fn steps_for(scene: &Scene, seconds: f64) -> u64 {
    // `as` saturates: negative and NaN give 0, beyond range u64::MAX.
    (seconds / scene.simulation.dt()).round() as u64
}

/// The simulated time of frame `frame` of `scene`, seconds: `(f K) dt` computed as one
/// product (docs/physics.md §6), so every output names a frame's time with the same bits.
pub fn frame_time(scene: &Scene, frame: u64) -> f64 {
    (frame * scene.every) as f64 * scene.simulation.dt()
}

/// The most steps a still at a chosen time may take: beyond this it is years of computing
/// away.
pub const MAX_STILL_STEPS: f64 = 1e12;

/// The steps from the start to simulated time `at` seconds (`None`: the scene's end), as
/// `render --at` takes it: refused when `at` is negative or not finite, or lies more than
/// [`MAX_STILL_STEPS`] steps away.
///
/// ```
/// let scene = hooke::source::build("chain", &Default::default()).unwrap();
/// assert_eq!(hooke::driver::steps_to(&scene, None).unwrap(), scene.steps);
/// assert!(hooke::driver::steps_to(&scene, Some(1e300)).is_err());
/// assert!(hooke::driver::steps_to(&scene, Some(-1.0)).is_err());
/// ```
pub fn steps_to(scene: &Scene, at: Option<f64>) -> Result<u64> {
    let Some(t) = at else {
        return Ok(scene.steps);
    };
    if !(t.is_finite() && t >= 0.0) {
        bail_input!("--at: expected a time in seconds >= 0, found {}", Num(t));
    }
    let dt = scene.simulation.dt();
    let steps = (t / dt).round();
    if steps > MAX_STILL_STEPS {
        bail_input!(
            "--at {} s is {steps:.1e} steps of dt = {} s, more than the {MAX_STILL_STEPS:.0e} a \
             still may take; choose an earlier time or a larger --dt",
            Num(t),
            Num(dt),
        );
    }
    Ok(steps as u64)
}

/// Steps `n` times, one at a time so that an interrupt is answered within a step.
fn steps(scene: &mut Scene, n: u64, bar: &dyn Progress) -> Result<()> {
    let _polling = interrupt::Polling::start();
    for _ in 0..n {
        interrupt::check(&scene.simulation)?;
        let stepped = scene.simulation.step();
        say_notices(scene);
        stepped?;
        // A large step an interrupt cut short (`Simulation::set_cancel`) is no state to
        // write: stop before any frame of it.
        interrupt::check_after_step(&scene.simulation)?;
        bar.set(scene.simulation.steps());
    }
    Ok(())
}

/// Steps `scene` to its end, calling `on_frame(frame, scene)` at frame 0 and after every
/// `scene.every` steps. A divergence comes back as an error holding a
/// [`hooke_core::Divergence`], an interrupt as one holding an [`interrupt::Interrupted`].
pub fn drive(scene: &mut Scene, mut on_frame: impl FnMut(u64, &Scene) -> Result<()>) -> Result<()> {
    let (total, every) = (scene.steps, scene.every);
    let bar = progress(scene, total);
    // A frame being written when an interrupt comes is finished before the run stops.
    let _polling = interrupt::Polling::start();
    on_frame(0, scene)?;
    for frame in 1..=total / every {
        steps(scene, every, bar.as_ref())?;
        on_frame(frame, scene)?;
    }
    // Steps past the last full frame are still run: the run's length is what was asked for.
    steps(scene, total % every, bar.as_ref())?;
    bar.finish();
    tally_notices(scene);
    tally_unsolved(scene);
    Ok(())
}

/// Steps `scene` `n` times without frames, interruptible, with progress on long runs.
pub fn advance(scene: &mut Scene, n: u64) -> Result<()> {
    let bar = progress(scene, n);
    steps(scene, n, bar.as_ref())?;
    bar.finish();
    tally_notices(scene);
    tally_unsolved(scene);
    Ok(())
}

/// Steps `scene` through `owed` seconds of simulated time in whole steps, as a viewer
/// keeping pace with the wall clock does, stopping early when `budget` of wall-clock time is
/// spent or an interrupt arrives. Returns the time still owed: under one step, or zero when
/// the budget ran out (the backlog is dropped, so a slow scene runs slower than real time
/// instead of falling ever further behind).
///
/// ```
/// use std::time::Duration;
/// let mut scene = hooke::source::build("chain", &Default::default()).unwrap();
/// let dt = scene.simulation.dt();
/// let left = hooke::driver::catch_up(&mut scene, 10.5 * dt, Duration::from_secs(60)).unwrap();
/// assert_eq!(scene.simulation.steps(), 10);
/// assert!((left - 0.5 * dt).abs() < 1e-12);
/// ```
pub fn catch_up(scene: &mut Scene, mut owed: f64, budget: Duration) -> Result<f64> {
    let (dt, started) = (scene.simulation.dt(), Instant::now());
    let _polling = interrupt::Polling::start();
    while owed >= dt {
        interrupt::check(&scene.simulation)?;
        let stepped = scene.simulation.step();
        say_notices(scene);
        stepped?;
        owed -= dt;
        if started.elapsed() > budget {
            return Ok(0.0);
        }
    }
    Ok(owed)
}
