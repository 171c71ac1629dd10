//! `hooke bench cloth`: the cloth-N solver workload, with the memory bandwidth measured
//! beside it (the STREAM triad) as the limit a step's traffic sets.

use super::{StepTimes, reorder, threads, use_kernel};
use anyhow::{Result, bail};
use hooke_core::{Integrator, Kernel};
use hooke_scene::spec::{AeroSpec, AirSpec, Finite, NonNegative, Positive};
use hooke_scene::workload;
use hooke_scene::{Overrides, Scene};
use serde::Serialize;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

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

pub(super) fn workload(n: usize, steps: u64, integrator: Integrator, air: bool) -> Result<Scene> {
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

#[allow(clippy::too_many_arguments)]
pub(super) fn cloth(
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
