//! `hooke`: run, render and inspect mass-spring scenes.

#![forbid(unsafe_code)]

mod advice;
mod bench;
mod check;
mod convert;
mod drape;
mod memory;
mod picture;
mod report;
mod risks;
mod run;
#[cfg(feature = "view")]
mod view;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use hooke::{draw, output, source};
use hooke_cli::args::ViewArgs;
use hooke_core::Integrator;
use hooke_scene::Overrides;
use std::path::PathBuf;
use std::process::ExitCode;

/// Mass-spring simulation you can trust: nine built-in scenes (the course's five among them),
/// jello worlds, your own scene files.
#[derive(Parser)]
#[command(name = "hooke", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a scene: a built-in name, a .toml scene file or a .w jello world.
    Run(RunArgs),
    /// Render a still of a scene at a given time to PNG.
    Render(RenderArgs),
    /// The main job: simulate the nine built-in scenes and write a still of each plus an
    /// animation.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        #[command(flatten)]
        view: ViewArgs,
    },
    /// Run the checks that show the physics is right (convergence, closed forms, energy,
    /// goldens, contacts, worlds, determinism, speed) and write them as a page:
    /// DIR/index.html with its plots, and every number in DIR/report.json. Exit status: 0
    /// every check passed, 1 a check failed, 2 the report could not run.
    Report {
        /// Output folder.
        dir: PathBuf,
        /// Shorter sweeps and runs and the three quickest scenes: under half a minute.
        #[arg(long)]
        quick: bool,
    },
    /// Cusick's drape test (BS 5058): a disc of MATERIAL on a round pedestal, repeated;
    /// prints the drape coefficient and node counts, or with --fit-dc the bending rigidity
    /// that gives a measured coefficient.
    Drape(drape::DrapeArgs),
    /// List the built-in scenes.
    Scenes,
    /// Print a built-in scene as TOML (`hooke run` accepts it and reproduces the same run).
    Scene {
        /// Built-in scene name.
        name: String,
    },
    /// Estimate the highest frequency of a scene and the largest stable step per integrator.
    Check {
        /// Built-in name, .toml scene or .w world.
        scene: String,
        #[command(flatten)]
        setup: SetupArgs,
    },
    /// Show scenes live in a window (TAB cycles, R replays, drag rotates, SHIFT+drag zooms).
    #[cfg(feature = "view")]
    View(view::ViewArgs),
    /// Benchmarks: the cloth-N solver workload and the rasterizer.
    #[command(subcommand)]
    Bench(bench::Bench),
    /// Convert between a jello world (.w) and a scene file (.toml), by the files' extensions.
    Convert {
        /// Input file (.w or .toml).
        input: PathBuf,
        /// Output file (.toml or .w).
        output: PathBuf,
    },
}

/// Options that change what is simulated.
#[derive(Args, Clone, Default)]
struct SetupArgs {
    /// Integrator: euler, symplectic, midpoint, rk4, implicit, vbd (block descent: one
    /// implicit step per display frame that keeps every surface out of still colliders and
    /// other surfaces; a pinned or squeezed particle in a moving collider's path cannot be,
    /// and the run warns when one is, docs/physics.md §4.1) or newton (the same step solved
    /// by Newton's method: for stiff and volumetric bodies, §4.2). `hooke check` says what
    /// each integrator promises for a scene.
    #[arg(long)]
    integrator: Option<Integrator>,
    /// Step size in seconds.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_seconds)]
    dt: Option<f64>,
    /// Run this many steps.
    #[arg(long, conflicts_with = "duration",
          value_parser = clap::value_parser!(u64).range(1..=hooke_scene::MAX_STEPS))]
    steps: Option<u64>,
    /// Run this many seconds of simulated time.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_seconds)]
    duration: Option<f64>,
    /// Replace the scene's table with this OBJ file (relative to the current folder), or
    /// `cylinder` for the analytic one.
    #[arg(long, value_name = "OBJ|cylinder")]
    table: Option<String>,
    /// Block descent: a step ends when its last iteration moved no particle faster than
    /// this, m/s (default 0.01).
    #[arg(long, value_name = "M/S", allow_negative_numbers = true, value_parser = parse_speed)]
    tolerance: Option<f64>,
    /// Block descent: the most iterations a step takes (default 24).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=100_000))]
    iterations: Option<u64>,
}

/// A speed in m/s: finite and positive.
fn parse_speed(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("expected a speed in m/s > 0, found '{s}'")),
    }
}

/// A frame cadence: a whole number of steps, at least 1.
fn parse_every(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(k) if k >= 1 => Ok(k),
        _ => Err(format!(
            "expected a whole number of steps >= 1, found '{s}'"
        )),
    }
}

/// A time in seconds: finite and positive.
pub(crate) fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("expected a time in seconds > 0, found '{s}'")),
    }
}

impl SetupArgs {
    /// The overrides; a table file is resolved against the current folder, as any path on
    /// the command line is (not against the scene file's folder).
    fn overrides(&self) -> anyhow::Result<Overrides> {
        let table = self
            .table
            .as_deref()
            .map(hooke::source::table)
            .transpose()?;
        Ok(Overrides {
            integrator: self.integrator,
            dt: self.dt,
            steps: self.steps,
            duration: self.duration,
            every: None,
            table,
            tolerance: self.tolerance,
            iterations: self.iterations,
        })
    }
}

#[derive(Args)]
struct RunArgs {
    /// Built-in name, .toml scene or .w world.
    scene: String,
    #[command(flatten)]
    setup: SetupArgs,
    /// A frame every K steps.
    #[arg(long, value_name = "K", value_parser = parse_every)]
    every: Option<u64>,
    /// Write the trajectory here (CSV as in docs/physics.md §6).
    #[arg(long, value_name = "FILE.csv")]
    trajectory: Option<PathBuf>,
    /// Print a summary line per frame: energies, bounding box, max speed, max penetration.
    #[arg(long)]
    summary: bool,
    /// Write every frame as a numbered PNG into this folder.
    #[arg(long, value_name = "DIR")]
    frames: Option<PathBuf>,
    /// Write the frames as a looping GIF animation.
    #[arg(long, value_name = "FILE.gif")]
    gif: Option<PathBuf>,
    /// Export the frames for other tools, the format from the path: FILE.usda (a USD stage,
    /// Y-up, metres, a time code per frame), FILE.pc2 (Blender's point cache of one body,
    /// with its mesh as FILE.obj beside it) or DIR/ with --format (a file per frame, or with
    /// pc2 a point cache per body, DIR/NAME.pc2 and DIR/NAME.obj).
    #[arg(long, value_name = "PATH")]
    export: Option<PathBuf>,
    /// The files of a folder export: ply (binary, with normals) or obj (with colliders), a
    /// file per frame; or pc2, Blender's point cache per body.
    #[arg(long, requires = "export")]
    format: Option<hooke::export::FolderFormat>,
    /// The body a .pc2 export caches (default: the scene's first).
    #[arg(long, value_name = "NAME", requires = "export")]
    body: Option<String>,
    #[command(flatten)]
    view: ViewArgs,
}

#[derive(Args)]
struct RenderArgs {
    /// Built-in name, .toml scene or .w world.
    scene: String,
    /// Simulated time of the still, seconds (default: the end of the scene's run).
    #[arg(long, allow_negative_numbers = true)]
    at: Option<f64>,
    /// Output PNG (the file name must end in .png).
    #[arg(short, long, value_name = "FILE.png")]
    output: PathBuf,
    #[command(flatten)]
    setup: SetupArgs,
    #[command(flatten)]
    view: ViewArgs,
}

/// Leaves quietly, as a Unix filter does, when the reader of standard output has gone
/// (`hooke bench cloth | head -1`): `println!` panics on a closed pipe, and this hook turns
/// that panic into the status of a process killed by SIGPIPE (128 + 13) without a
/// backtrace. Every other panic goes to the default hook.
fn quiet_on_closed_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        // `PanicHookInfo::payload_as_str` would do, from Rust 1.91; the crate builds on 1.89.
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or_default();
        if message.starts_with("failed printing to stdout") && message.contains("os error 32") {
            std::process::exit(141);
        }
        default(info);
    }));
}

fn main() -> ExitCode {
    quiet_on_closed_pipe();
    let cli = Cli::parse();
    // `hooke report` tells a failed check (1) from a report that could not run (2), as
    // pytest tells failed tests from a usage error; every other command fails with 1.
    let could_not_run = match cli.command {
        Command::Report { .. } => ExitCode::from(report::COULD_NOT_RUN),
        _ => ExitCode::FAILURE,
    };
    hooke::interrupt::install();
    hooke::progress::install(Box::new(hooke_cli::bars::Bars));
    // Everything but the window runs on a worker of the thread pool: the solver's parallel
    // loops are then cheap joins, not injections that wake the pool through the kernel on
    // every call (the 512-particle jelly steps about 1.6× faster so). The viewer keeps the
    // main thread, as windowing systems prefer, and `bench` builds its own pool (one pool
    // waiting inside another would spin on a core the measured one needs).
    let result = match cli.command {
        #[cfg(feature = "view")]
        Command::View(_) => dispatch(cli.command),
        Command::Bench(_) => dispatch(cli.command),
        // A bad RAYON_NUM_THREADS is refused; a pool that cannot start leaves the work here.
        command => match hooke::threads::count(None, "--threads") {
            Ok(count) => match hooke::threads::build(count) {
                Ok(pool) => pool.install(|| dispatch(command)),
                Err(_) => dispatch(command),
            },
            Err(e) => Err(e.into()),
        },
    };
    match result {
        Ok(code) => code,
        Err(e) if e.downcast_ref().is_some_and(hooke::interrupt::is_interrupt) => {
            eprintln!("{e:#}: stopped");
            ExitCode::from(hooke::interrupt::EXIT_INTERRUPTED)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            could_not_run
        }
    }
}

fn dispatch(command: Command) -> Result<ExitCode> {
    match command {
        Command::Run(args) => run::run(&args),
        Command::Render(args) => picture::render(&args),
        Command::Demo { out, view } => picture::demo(&out, &view.view()),
        Command::Report { dir, quick } => report::report(&dir, quick),
        Command::Drape(args) => Ok(drape::drape(&args)?),
        Command::Scenes => {
            for (name, make) in hooke_scene::builtin::BUILTINS {
                println!("{name:<14} {}", make().description);
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Scene { name } => {
            let spec = source::read(&name)?.spec.with_contact_defaults();
            print!("{}", hooke_scene::to_toml(&spec));
            Ok(ExitCode::SUCCESS)
        }
        Command::Check { scene, setup } => check::check(&scene, &setup),
        Command::Convert { input, output } => convert::convert(&input, &output),
        Command::Bench(bench) => bench::run(&bench),
        #[cfg(feature = "view")]
        Command::View(args) => view::run(&args),
    }
}
