//! `hooke bench`: the cloth-N solver workload (`cloth.rs`), any scene's steps (`scene.rs`)
//! and the rasterizer (`render.rs`).
//!
//! Figures are wall-clock times of release builds on whatever machine runs them; nothing
//! here is asserted. `--json` prints one object per measurement for scripts.

mod cloth;
mod render;
mod scene;

use crate::source;
use anyhow::Result;
use hooke_core::{Integrator, Kernel, Renumbering, Simulation};
use hooke_scene::{Overrides, workload};
use std::process::ExitCode;
use std::time::Instant;

use cloth::cloth;
use render::renders;
use scene::scene_steps;

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

fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    Ok(hooke::threads::pool(threads, "--threads")?)
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

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// `1 thread`, `2 threads`.
fn threads(n: usize) -> String {
    if n == 1 {
        "1 thread".to_string()
    } else {
        format!("{n} threads")
    }
}
