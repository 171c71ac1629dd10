//! `hooke bench`: the cloth-N solver workload and the rasterizer benchmark.
//!
//! Figures are wall-clock times of release builds on whatever machine runs them; nothing
//! here is asserted. `--json` prints one object per measurement for scripts.

use crate::draw::{DEFAULT_YAW_PITCH, Style, draw, frame_camera};
use crate::source;
use anyhow::{Context, Result, bail};
use hooke_core::{Integrator, Kernel, Renumbering, Simulation};
use hooke_render::{RenderOptions, Renderer};
use hooke_scene::spec::{AeroSpec, AirSpec, Finite, NonNegative, Positive};
use hooke_scene::workload;
use hooke_scene::{Overrides, Scene};
use image::{ImageFormat, RgbaImage};
use serde::Serialize;
use std::io::Cursor;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

/// What `hooke bench` measures.
#[derive(clap::Subcommand)]
pub enum Bench {
    /// The cloth-N workload (docs/benchmarks.md): steps/s and spring updates/s.
    Cloth {
        /// Particles along each side.
        #[arg(long, default_value_t = 256)]
        n: usize,
        /// Measured steps (the centre particle's y is reported after them).
        #[arg(long, default_value_t = workload::WORKLOAD_STEPS)]
        steps: u64,
        /// Worker threads (default: one per core).
        #[arg(long)]
        threads: Option<usize>,
        /// Integrator.
        #[arg(long, default_value_t = Integrator::Symplectic)]
        integrator: Integrator,
        /// Force-loop compilation (default: the widest this CPU runs).
        #[arg(long)]
        kernel: Option<Kernel>,
        /// The workload in moving air (density 1.225 kg/m³, wind (2, 0, 1) m/s, drag 1,
        /// lift 0.3 on every triangle): compare with a run without it for the cost of air.
        #[arg(long)]
        air: bool,
        /// Number the particles at random (by this seed), as a mesh that arrives unordered,
        /// then renumber them for locality as any simulation can (`Simulation::renumber_for_locality`).
        #[arg(long, value_name = "SEED")]
        shuffle: Option<u64>,
        /// With `--shuffle`: keep the random numbering, to measure what renumbering gains.
        #[arg(long, requires = "shuffle")]
        keep_order: bool,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Any scene (built-in, .toml or .w world): steps per second with its own integrator.
    /// Explicit integrators are timed for `--steps` after 100 warm-up steps; the large-step
    /// ones (implicit, vbd) from the scene's start, landing included, for its whole run (or
    /// `--steps`), since at their step a warm-up would skip seconds of what is simulated.
    Scene {
        /// Built-in name, .toml scene or .w world.
        scene: String,
        /// Measured steps (default: 20000; for implicit and vbd the scene's whole run).
        #[arg(long)]
        steps: Option<u64>,
        /// Integrator (default: the scene's).
        #[arg(long)]
        integrator: Option<Integrator>,
        /// Step size in seconds (default: the scene's).
        #[arg(long)]
        dt: Option<f64>,
        /// Replace the table: an OBJ file, or `cylinder` for the analytic one.
        #[arg(long, value_name = "FILE.obj|cylinder")]
        table: Option<String>,
        /// Force-loop compilation (default: the widest this CPU runs).
        #[arg(long)]
        kernel: Option<Kernel>,
        /// Worker threads (default: one per core).
        #[arg(long)]
        threads: Option<usize>,
        /// Block descent: the stopping tolerance, m/s (default: the scene's, or 0.01).
        #[arg(long)]
        tolerance: Option<f64>,
        /// Block descent: the iteration budget per step (default: the scene's, or 24).
        #[arg(long)]
        iterations: Option<u64>,
        /// Also measure each block-descent step's residual (a sweep's cost more a step).
        #[arg(long)]
        residual: bool,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Rasterizer: render and PNG-encode times of stills.
    Render {
        /// What to draw: `cloth-N` is the workload grid of N×N particles (two triangles per
        /// square) as built; anything else is a scene (built-in, .toml or .w) run to its end.
        #[arg(default_values_t = ["cloth-256".to_string(), "cloth-1024".to_string(), "cloth-table".to_string()])]
        targets: Vec<String>,
        /// Also write each image as TARGET.png into this folder, to look at.
        #[arg(long, value_name = "DIR")]
        save: Option<std::path::PathBuf>,
        /// Image size.
        #[arg(long, default_value = "1024x1024", value_parser = hooke_cli::args::parse_size)]
        size: (u32, u32),
        /// Samples per pixel along each axis, 1 to 4 (2 = 4× anti-aliasing).
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=4))]
        supersample: u32,
        /// Timed repetitions, at least 1; the median is reported.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u16).range(1..))]
        repeat: u16,
        /// Worker threads (default: one per core).
        #[arg(long)]
        threads: Option<usize>,
        /// Print JSON objects instead of text.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Serialize)]
struct ClothFigures {
    n: usize,
    steps: u64,
    threads: usize,
    integrator: String,
    kernel: String,
    /// Whether the workload ran in moving air (`--air`).
    air: bool,
    /// The seed the particles were numbered at random by (`--shuffle`), and whether they
    /// were then renumbered for locality.
    shuffle: Option<u64>,
    renumbered: bool,
    springs: usize,
    seconds: f64,
    steps_per_s: f64,
    spring_updates_per_s: f64,
    /// The median and the shortest of the steps' own times, and the rate at the median:
    /// on a shared machine, where other work stalls some steps, these tell those stalls
    /// from the solver's own speed.
    median_step_s: f64,
    fastest_step_s: f64,
    median_spring_updates_per_s: f64,
    center_y: f64,
    /// The STREAM triad's bandwidth measured in the same run on the same threads, bytes/s.
    triad_bytes_per_s: f64,
    /// The least a step must move: every particle's position and velocity read and written
    /// (96 bytes) and the spring list read (two 4-byte ends and an 8-byte rest length).
    bytes_per_step: f64,
    /// The steps per second the triad's bandwidth allows, and the median step's share of it.
    limit_steps_per_s: f64,
    share_of_limit: f64,
}

/// Elements per array of [`triad`]: three arrays of 64 MiB, far beyond any cache.
const TRIAD_LEN: usize = 1 << 23;

/// The STREAM triad `a = b + s c` on the current rayon pool, in bytes per second (24 per
/// element, as STREAM counts them): the best of five passes, after one that pages the
/// arrays in.
fn triad() -> f64 {
    use rayon::prelude::*;
    let (mut a, b, c) = (
        vec![0.0f64; TRIAD_LEN],
        vec![1.0f64; TRIAD_LEN],
        vec![2.0f64; TRIAD_LEN],
    );
    let chunk = TRIAD_LEN.div_ceil(4 * rayon::current_num_threads());
    let mut best = f64::INFINITY;
    for pass in 0..6 {
        let started = Instant::now();
        a.par_chunks_mut(chunk)
            .zip(b.par_chunks(chunk).zip(c.par_chunks(chunk)))
            .for_each(|(a, (b, c))| {
                for ((a, b), c) in a.iter_mut().zip(b).zip(c) {
                    *a = b + 3.0 * c;
                }
            });
        if pass > 0 {
            best = best.min(started.elapsed().as_secs_f64());
        }
    }
    std::hint::black_box(&a);
    (24 * TRIAD_LEN) as f64 / best
}

/// Step times of a timed run: the median and the shortest, over at most the first
/// [`StepTimes::KEPT`] steps.
struct StepTimes(Vec<f64>);

impl StepTimes {
    const KEPT: usize = 1 << 20;

    /// Runs `steps` steps of `simulation`, timing each and calling `after` untimed after
    /// each; returns the times and the total.
    fn run(
        simulation: &mut Simulation,
        steps: u64,
        mut after: impl FnMut(&Simulation),
    ) -> Result<(Self, f64)> {
        let mut times = Vec::with_capacity((steps as usize).min(Self::KEPT));
        let started = Instant::now();
        let mut last = started;
        let mut untimed = std::time::Duration::ZERO;
        let _polling = hooke::interrupt::Polling::start();
        for _ in 0..steps {
            // An atomic load per step: far below the timer reads around it.
            hooke::interrupt::check(simulation)?;
            simulation.step()?;
            let now = Instant::now();
            after(simulation);
            let resumed = Instant::now();
            untimed += resumed - now;
            if times.len() < Self::KEPT {
                times.push((now - last).as_secs_f64());
            }
            last = resumed;
        }
        times.sort_by(f64::total_cmp);
        Ok((Self(times), (last - started - untimed).as_secs_f64()))
    }

    fn median(&self) -> f64 {
        self.0[self.0.len() / 2]
    }

    fn fastest(&self) -> f64 {
        self.0[0]
    }
}

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
}

#[derive(Serialize)]
struct RenderFigures {
    scene: String,
    triangles: usize,
    width: u32,
    height: u32,
    samples_per_pixel: u32,
    threads: usize,
    /// With shadows (the default).
    render_ms: f64,
    /// The same frame without shadows, timed in the same loop.
    render_without_shadows_ms: f64,
    /// `render_ms / render_without_shadows_ms`.
    shadow_cost: f64,
    png_encode_ms: f64,
}

fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    Ok(hooke::threads::pool(threads, "--threads")?)
}

fn workload(n: usize, steps: u64, integrator: Integrator, air: bool) -> Result<Scene> {
    if !(3..=2048).contains(&n) {
        bail!("--n: expected a cloth size from 3 to 2048, found {n}");
    }
    if steps == 0 {
        bail!("--steps: expected at least 1");
    }
    let mut spec = workload::cloth(n);
    if air {
        let f3 = |v: [f64; 3]| v.map(Finite::of);
        spec.simulation.air = Some(AirSpec {
            density: Positive::of(hooke_core::forces::air::SEA_LEVEL_DENSITY),
            wind: f3([2.0, 0.0, 1.0]),
            gust: None,
        });
        spec.bodies[0].aero = Some(AeroSpec {
            drag: NonNegative::of(1.0),
            lift: Finite::of(0.3),
        });
    }
    Overrides {
        integrator: Some(integrator),
        steps: Some(steps),
        ..Overrides::default()
    }
    .apply(&mut spec)?;
    Ok(spec.build(Path::new("."))?)
}

pub fn run(bench: &Bench) -> Result<ExitCode> {
    match bench {
        Bench::Cloth {
            n,
            steps,
            threads,
            integrator,
            kernel,
            air,
            shuffle,
            keep_order,
            json,
        } => {
            let order = shuffle.map(|seed| (seed, !keep_order));
            pool(*threads)?.install(|| cloth(*n, *steps, *integrator, *kernel, *air, order, *json))
        }
        Bench::Scene {
            scene,
            steps,
            integrator,
            dt,
            table,
            kernel,
            threads,
            tolerance,
            iterations,
            residual,
            json,
        } => {
            let overrides = Overrides {
                integrator: *integrator,
                dt: *dt,
                table: table.as_deref().map(source::table).transpose()?,
                tolerance: *tolerance,
                iterations: *iterations,
                ..Overrides::default()
            };
            pool(*threads)?
                .install(|| scene_steps(scene, &overrides, *kernel, (*steps, *residual), *json))
        }
        Bench::Render {
            targets,
            save,
            size,
            supersample,
            repeat,
            threads,
            json,
        } => pool(*threads)?.install(|| {
            renders(
                targets,
                save.as_deref(),
                *size,
                *supersample,
                usize::from(*repeat),
                *json,
            )
        }),
    }
}

/// Sets the force loop's compilation, if one was asked for.
fn use_kernel(sim: &mut Simulation, kernel: Option<Kernel>) -> Result<()> {
    if let Some(kernel) = kernel {
        sim.set_kernel(kernel)
            .map_err(|best| anyhow::anyhow!("--kernel {kernel}: this CPU runs at most {best}"))?;
    }
    Ok(())
}

/// Numbers the workload's particles at random by `seed` and, if `renumber`, then for
/// locality; returns the new number of particle `tracked`.
fn reorder(sim: &mut Simulation, (seed, renumber): (u64, bool), tracked: usize) -> usize {
    let shuffled = Renumbering::shuffled(sim.particles().len(), &sim.bodies(), seed);
    sim.renumber(&shuffled)
        .expect("a shuffle within the bodies fits");
    let mut at = shuffled.new_index(tracked);
    if renumber {
        at = sim.renumber_for_locality().new_index(at);
    }
    at
}

#[allow(clippy::too_many_arguments)]
fn cloth(
    n: usize,
    steps: u64,
    integrator: Integrator,
    kernel: Option<Kernel>,
    air: bool,
    order: Option<(u64, bool)>,
    json: bool,
) -> Result<ExitCode> {
    // Warm-up on a separate copy: page in the buffers and start the workers, so the measured
    // run starts from the workload's initial state.
    let mut warm = workload(n, steps, integrator, air)?;
    use_kernel(&mut warm.simulation, kernel)?;
    if let Some(order) = order {
        reorder(&mut warm.simulation, order, 0);
    }
    warm.simulation.advance(steps.min(20))?;
    let mut scene = workload(n, steps, integrator, air)?;
    use_kernel(&mut scene.simulation, kernel)?;
    let centre = match order {
        Some(order) => reorder(&mut scene.simulation, order, workload::centre(n)),
        None => workload::centre(n),
    };
    let (times, seconds) = StepTimes::run(&mut scene.simulation, steps, |_| ())?;
    let springs = scene.simulation.model().springs.len();
    let triad_bytes_per_s = triad();
    let bytes_per_step = (96 * n * n + 16 * springs) as f64;
    let limit_steps_per_s = triad_bytes_per_s / bytes_per_step;
    let figures = ClothFigures {
        n,
        steps,
        threads: rayon::current_num_threads(),
        integrator: integrator.to_string(),
        kernel: scene.simulation.workspace().kernel().to_string(),
        air,
        shuffle: order.map(|(seed, _)| seed),
        renumbered: order.is_some_and(|(_, renumber)| renumber),
        springs,
        seconds,
        steps_per_s: steps as f64 / seconds,
        spring_updates_per_s: (springs as u64 * steps) as f64 / seconds,
        median_step_s: times.median(),
        fastest_step_s: times.fastest(),
        median_spring_updates_per_s: springs as f64 / times.median(),
        center_y: scene.simulation.particles().x[centre].y,
        triad_bytes_per_s,
        bytes_per_step,
        limit_steps_per_s,
        share_of_limit: 1.0 / times.median() / limit_steps_per_s,
    };
    if json {
        println!("{}", serde_json::to_string(&figures)?);
    } else {
        println!(
            "cloth N={n}{}{}: {springs} springs, {steps} {integrator} steps on {} ({} \
             kernel, {} batches, runs by {}) in {:.3} s: {:.1} steps/s, {:.1} M spring updates/s; median step {:.3} \
             ms ({:.1} M/s), fastest {:.3} ms; centre y = {:.12}\n  bandwidth: triad {:.1} GB/s, \
             a step moves at least {:.1} MB, so at most {:.1} steps/s; the median step runs at \
             {:.2} of that",
            if air { " in air" } else { "" },
            match order {
                Some((seed, true)) => format!(", shuffled by {seed} and renumbered"),
                Some((seed, false)) => format!(", shuffled by {seed}"),
                None => String::new(),
            },
            threads(figures.threads),
            figures.kernel,
            scene.simulation.workspace().kernel().batches(),
            scene.simulation.workspace().kernel().run_lanes(),
            seconds,
            figures.steps_per_s,
            figures.spring_updates_per_s / 1e6,
            figures.median_step_s * 1e3,
            figures.median_spring_updates_per_s / 1e6,
            figures.fastest_step_s * 1e3,
            figures.center_y,
            triad_bytes_per_s / 1e9,
            bytes_per_step / 1e6,
            limit_steps_per_s,
            figures.share_of_limit
        );
    }
    Ok(ExitCode::SUCCESS)
}

fn scene_steps(
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
                            "; time: detection {:.0}% ({:.2} ms each), sweeps {:.0}% ({:.0} ns a \
                         particle), coarse correction {:.0}%, acceleration {:.0}%, rest {:.0}%",
                            100.0 * t.detection / seconds,
                            t.detection_ms,
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

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn renders(
    targets: &[String],
    save: Option<&Path>,
    (width, height): (u32, u32),
    supersample: u32,
    repeat: usize,
    json: bool,
) -> Result<ExitCode> {
    let options = RenderOptions {
        width,
        height,
        supersample,
        ..RenderOptions::default()
    };
    let mut scenes: Vec<(String, Scene)> = Vec::new();
    for target in targets {
        let grid = target
            .strip_prefix("cloth-")
            .and_then(|n| n.parse::<usize>().ok());
        let scene = match grid {
            Some(n) => workload(n, 1, Integrator::Symplectic, false)
                .with_context(|| format!("target {target}"))?,
            None => {
                let mut scene = source::build(target, &Overrides::default())?;
                let steps = scene.steps;
                hooke::driver::advance(&mut scene, steps)?;
                scene
            }
        };
        scenes.push((target.clone(), scene));
    }
    if let Some(dir) = save {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output folder {}", dir.display()))?;
    }

    for (name, scene) in &scenes {
        let list = draw(scene, Style::Solid);
        let camera = frame_camera(scene, DEFAULT_YAW_PITCH.0, DEFAULT_YAW_PITCH.1);
        // As an animation renders: one renderer, its buffers reused from frame to frame.
        let mut renderer = Renderer::default();
        let mut times = Vec::new();
        let mut plain = Vec::new();
        let mut pixels = Vec::new();
        let unshadowed = RenderOptions {
            shadows: false,
            ..options
        };
        // Interleaved, so that both see the same load on a shared machine.
        for _ in 0..repeat {
            let started = Instant::now();
            pixels = renderer.render(&list, &camera, &options);
            times.push(started.elapsed().as_secs_f64() * 1e3);
            let started = Instant::now();
            renderer.render(&list, &camera, &unshadowed);
            plain.push(started.elapsed().as_secs_f64() * 1e3);
        }
        let image = RgbaImage::from_raw(width, height, pixels).context("image size")?;
        if let Some(dir) = save {
            let name = Path::new(name.as_str())
                .file_stem()
                .map_or_else(|| name.clone(), |s| s.to_string_lossy().into_owned());
            hooke::image_out::write_png(&dir.join(format!("{name}.png")), &image)?;
        }
        let mut encode = Vec::new();
        for _ in 0..repeat {
            let started = Instant::now();
            let mut bytes = Vec::new();
            image.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)?;
            encode.push(started.elapsed().as_secs_f64() * 1e3);
        }
        let figures = RenderFigures {
            scene: name.clone(),
            triangles: list.triangle_count(),
            width,
            height,
            samples_per_pixel: options.supersample * options.supersample,
            threads: rayon::current_num_threads(),
            render_ms: median(times.clone()),
            render_without_shadows_ms: median(plain.clone()),
            shadow_cost: median(times) / median(plain),
            png_encode_ms: median(encode),
        };
        if json {
            println!("{}", serde_json::to_string(&figures)?);
        } else {
            println!(
                "{:<12} {:>8} triangles at {width}x{height}, {}x AA, {}: render {:.1} ms \
                 ({:.1} ms without shadows: {:.2}x), PNG encode {:.1} ms (median of {repeat})",
                figures.scene,
                figures.triangles,
                figures.samples_per_pixel,
                threads(figures.threads),
                figures.render_ms,
                figures.render_without_shadows_ms,
                figures.shadow_cost,
                figures.png_encode_ms
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `1 thread`, `2 threads`.
fn threads(n: usize) -> String {
    if n == 1 {
        "1 thread".to_string()
    } else {
        format!("{n} threads")
    }
}
