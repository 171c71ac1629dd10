//! `hooke bench scene`: any scene's steps timed, with the large-step solvers' counts and
//! block descent's time split by what it did.

use super::{StepTimes, threads, use_kernel};
use crate::source;
use anyhow::{Result, bail};
use hooke_core::{Integrator, Kernel};
use hooke_scene::Overrides;
use serde::Serialize;
use std::process::ExitCode;

#[derive(Serialize)]
struct SceneFigures {
    scene: String,
    dt: f64,
    /// Average conjugate-gradient iterations per step (implicit only).
    cg_iterations_per_step: f64,
    /// Average block-descent iterations and contact detections per step (vbd only).
    vbd_iterations_per_step: f64,
    vbd_detections_per_step: f64,
    /// The solver's iterations per step: block descent's, or conjugate gradients' (0 for the
    /// explicit integrators).
    iterations_per_step: f64,
    /// Steps that ended at an iteration cap without meeting the solver's stopping rule.
    capped_steps: u64,
    /// The largest residual a block-descent step ended with: the force left on a free
    /// particle over its weight (docs/physics.md §4.1; measured with `--residual`, else
    /// null).
    max_residual: Option<f64>,
    /// Block descent: the steps' final update over the step (the stopping rule's measure,
    /// m/s), median and largest; its stopping rule; parts per step (more than one with a
    /// moving collider or keyed pins).
    median_final_speed: f64,
    largest_final_speed: f64,
    tolerance: f64,
    iteration_budget: usize,
    parts_per_step: f64,
    /// Block descent: where the wall time went, seconds; they sum to `seconds`.
    time_split: Option<TimeSplit>,
    /// Whether the steps were timed from the scene's start (large-step integrators) or
    /// after a warm-up of 100 steps.
    from_start: bool,
    /// Wall seconds per simulated second.
    wall_per_simulated_s: f64,
    integrator: String,
    kernel: String,
    particles: usize,
    /// Particles not pinned at the end of the run.
    free_particles: usize,
    springs: usize,
    steps: u64,
    threads: usize,
    seconds: f64,
    steps_per_s: f64,
    /// As in [`ClothFigures`].
    median_step_s: f64,
    fastest_step_s: f64,
    /// The contact phase's share of the measured wall time (collider faces, features and
    /// self-collision), 0 to 1.
    contact_share: f64,
    /// Rebuilds of the contact candidate lists during the measured steps.
    contact_rebuilds: u64,
    /// The process's peak resident memory, MiB (the scene's build included), where the
    /// system says it (Linux).
    peak_resident_mib: Option<f64>,
}

/// Block descent's wall time by what it did, seconds.
#[derive(Serialize)]
struct TimeSplit {
    detection: f64,
    sweeps: f64,
    coarse_correction: f64,
    acceleration: f64,
    /// Everything else: the steps' set-up and end, the divergence and energy checks.
    rest: f64,
    /// One sweep's wall time over the free particles it visits, nanoseconds: the sweeps'
    /// time over (iterations × free particles).
    sweep_ns_per_particle: f64,
    /// One detection's wall time, milliseconds: the detection's time (recolouring, the
    /// step's targets and first guess included) over the detections.
    detection_ms: f64,
    /// The self-contact pair list's builds (part of `detection`), seconds, and how many
    /// there were per step.
    pair_list_building: f64,
    pair_list_builds_per_step: f64,
}

pub(super) fn scene_steps(
    name: &str,
    overrides: &Overrides,
    kernel: Option<Kernel>,
    (steps, residual): (Option<u64>, bool),
    json: bool,
) -> Result<ExitCode> {
    if steps == Some(0) {
        bail!("--steps: expected at least 1");
    }
    let mut scene = source::build(name, overrides)?;
    let whole_run = scene.steps;
    let sim = &mut scene.simulation;
    use_kernel(sim, kernel)?;
    sim.measure_residuals(residual);
    let times_before: hooke_core::SolveTimes = sim.workspace().solve_times();
    let from_start = sim.integrator() == Integrator::Implicit || sim.integrator().solves_contacts();
    let steps = match steps {
        Some(n) => n,
        None if from_start => whole_run,
        None => 20_000,
    };
    if !from_start {
        sim.advance(steps.min(100))?;
    }
    let mut cg_iterations = 0;
    let (mut vbd_iterations, mut vbd_detections) = (0, 0);
    let (mut capped_steps, mut max_residual) = (0, 0.0f64);
    let (mut final_speeds, mut parts) = (Vec::new(), 0u64);
    let contacts_before = sim.contact_stats();
    let (times, seconds) = StepTimes::run(sim, steps, |sim| {
        let w = sim.workspace();
        cg_iterations += w.cg_iterations();
        vbd_iterations += w.vbd_iterations();
        vbd_detections += w.vbd_detections();
        capped_steps += u64::from(w.capped());
        max_residual = max_residual.max(w.vbd_residual());
        final_speeds.push(w.vbd_last_speed());
        parts += u64::from(w.vbd_parts());
    })?;
    let contacts = sim.contact_stats();
    let vbd = sim.integrator().solves_contacts();
    let p = sim.particles();
    let free = (0..p.len()).filter(|&i| !p.is_pinned(i)).count();
    let split = vbd.then(|| {
        let now = sim.workspace().solve_times();
        let part = |a: std::time::Duration, b: std::time::Duration| (a - b).as_secs_f64();
        let detection = part(now.detection, times_before.detection);
        let sweeps = part(now.sweeps, times_before.sweeps);
        let coarse_correction = part(now.coarse, times_before.coarse);
        let acceleration = part(now.acceleration, times_before.acceleration);
        let per = |t: f64, n: f64| if n > 0.0 { t / n } else { 0.0 };
        TimeSplit {
            detection,
            sweeps,
            coarse_correction,
            acceleration,
            rest: seconds - detection - sweeps - coarse_correction - acceleration,
            sweep_ns_per_particle: 1e9 * per(sweeps, vbd_iterations as f64 * free as f64),
            detection_ms: 1e3 * per(detection, vbd_detections as f64),
            pair_list_building: part(now.pair_list_building, times_before.pair_list_building),
            pair_list_builds_per_step: per(
                (now.pair_list_builds - times_before.pair_list_builds) as f64,
                steps as f64,
            ),
        }
    });
    final_speeds.sort_by(f64::total_cmp);
    let rule = sim.workspace().stop_rule_of(sim.integrator());
    let figures = SceneFigures {
        cg_iterations_per_step: cg_iterations as f64 / steps as f64,
        vbd_iterations_per_step: vbd_iterations as f64 / steps as f64,
        vbd_detections_per_step: vbd_detections as f64 / steps as f64,
        iterations_per_step: (cg_iterations + vbd_iterations) as f64 / steps as f64,
        capped_steps,
        max_residual: residual.then_some(max_residual),
        median_final_speed: if vbd {
            final_speeds[final_speeds.len() / 2]
        } else {
            0.0
        },
        largest_final_speed: if vbd {
            final_speeds.last().copied().unwrap_or(0.0)
        } else {
            0.0
        },
        tolerance: rule.tolerance,
        iteration_budget: rule.iterations,
        parts_per_step: parts as f64 / steps as f64,
        time_split: split,
        from_start,
        wall_per_simulated_s: seconds / (steps as f64 * sim.dt()),
        dt: sim.dt(),
        scene: scene.spec.name.clone(),
        integrator: sim.integrator().to_string(),
        kernel: sim.workspace().kernel().to_string(),
        particles: sim.particles().len(),
        free_particles: free,
        springs: sim.model().springs.len(),
        steps,
        threads: rayon::current_num_threads(),
        seconds,
        steps_per_s: steps as f64 / seconds,
        median_step_s: times.median(),
        fastest_step_s: times.fastest(),
        contact_share: (contacts.seconds - contacts_before.seconds) / seconds,
        contact_rebuilds: contacts.rebuilds - contacts_before.rebuilds,
        peak_resident_mib: crate::memory::peak_resident_mib(),
    };
    if json {
        println!("{}", serde_json::to_string(&figures)?);
    } else {
        println!(
            "{}: {} particles, {} springs, {steps} {} steps of {} s on {} ({} kernel, \
             {} batches, runs by {}) in {:.3} s: {:.0} steps/s (median step {:.1} µs, fastest {:.1} µs), {:.3} s per \
             simulated second; contacts {:.0}% of the time ({} candidate rebuilds){}{}",
            figures.scene,
            figures.particles,
            figures.springs,
            figures.integrator,
            figures.dt,
            threads(figures.threads),
            figures.kernel,
            sim.workspace().kernel().batches(),
            sim.workspace().kernel().run_lanes(),
            seconds,
            figures.steps_per_s,
            figures.median_step_s * 1e6,
            figures.fastest_step_s * 1e6,
            seconds / (steps as f64 * figures.dt),
            100.0 * figures.contact_share,
            figures.contact_rebuilds,
            if cg_iterations > 0 {
                format!(
                    ", {:.1} CG iterations per step",
                    figures.cg_iterations_per_step
                )
            } else if vbd_iterations > 0 {
                format!(
                    ", {:.1} block-descent iterations and {:.2} detections per step, {} of \
                     {steps} steps at the budget of {} (tolerance {} m/s), final update median \
                     {:.2e} and largest {:.2e} m/s{}{}{}",
                    figures.vbd_iterations_per_step,
                    figures.vbd_detections_per_step,
                    figures.capped_steps,
                    figures.iteration_budget,
                    figures.tolerance,
                    figures.median_final_speed,
                    figures.largest_final_speed,
                    figures.max_residual.map_or(String::new(), |r| format!(
                        ", largest residual {r:.3e} of a weight"
                    )),
                    figures
                        .time_split
                        .as_ref()
                        .map_or(String::new(), |t| format!(
                            "; time: detection {:.0}% ({:.2} ms each; pair-list builds {:.0}%, \
                             {:.2} a step), sweeps {:.0}% ({:.0} ns a particle), coarse \
                             correction {:.0}%, acceleration {:.0}%, rest {:.0}%",
                            100.0 * t.detection / seconds,
                            t.detection_ms,
                            100.0 * t.pair_list_building / seconds,
                            t.pair_list_builds_per_step,
                            100.0 * t.sweeps / seconds,
                            t.sweep_ns_per_particle,
                            100.0 * t.coarse_correction / seconds,
                            100.0 * t.acceleration / seconds,
                            100.0 * t.rest / seconds
                        )),
                    if from_start {
                        " (timed from the start)"
                    } else {
                        ""
                    }
                )
            } else {
                String::new()
            },
            figures
                .peak_resident_mib
                .map_or(String::new(), |m| format!("; peak resident {m:.1} MiB"))
        );
    }
    Ok(ExitCode::SUCCESS)
}
