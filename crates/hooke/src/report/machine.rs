//! Determinism and speed on this machine: a hash of every frame of three runs on one
//! thread and on all of them (they must agree), and the cloth-N workload's rate
//! (`docs/benchmarks.md`) beside what the machine is.

use crate::Result;
use hooke_scene::Overrides;
use serde::Serialize;
use std::time::{Duration, Instant};

/// One run's hashes.
#[derive(Serialize)]
pub(crate) struct Hashes {
    pub(crate) run: String,
    pub(crate) one_thread: String,
    pub(crate) threads: usize,
    pub(crate) many_threads: String,
}

impl Hashes {
    /// Whether one thread and many gave the same bits.
    pub(crate) fn agree(&self) -> bool {
        self.one_thread == self.many_threads
    }
}

/// The workload's rate.
#[derive(Serialize)]
pub(crate) struct Speed {
    pub(crate) workload: String,
    pub(crate) threads: usize,
    pub(crate) steps_per_second: f64,
    pub(crate) spring_updates_per_second: f64,
    /// Wall seconds per simulated second of the built-in `cloth-table`.
    pub(crate) cloth_table_wall_per_simulated: f64,
}

/// What the machine is.
#[derive(Serialize)]
pub(crate) struct Machine {
    pub(crate) cpu: String,
    pub(crate) logical_cpus: usize,
    pub(crate) spring_kernel: String,
    pub(crate) os: String,
}

/// FNV-1a over the bits of every position and velocity.
fn hash(state: &hooke_core::Particles, into: &mut u64) {
    for v in state.x.iter().chain(&state.v) {
        for c in v.iter() {
            for b in c.to_bits().to_le_bytes() {
                *into ^= b as u64;
                *into = into.wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
}

/// The hash of every frame of `source` for `seconds`, on `pool`.
fn run_hash(source: &str, seconds: f64, pool: &rayon::ThreadPool) -> Result<String> {
    pool.install(|| {
        let overrides = Overrides {
            duration: Some(seconds),
            ..Overrides::default()
        };
        let mut scene = crate::source::build(source, &overrides)?;
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        crate::driver::drive(&mut scene, |_, scene| {
            hash(scene.simulation.particles(), &mut h);
            Ok(())
        })?;
        Ok(format!("{h:016x}"))
    })
}

/// The runs hashed: a cloth on its table, the flag in its wind, a jelly.
fn runs(quick: bool) -> Vec<(&'static str, f64)> {
    let t = if quick { 0.05 } else { 0.5 };
    vec![("cloth-table", t), ("flag", t), ("jello-cube", t)]
}

/// The threads the report's parallel runs take: `RAYON_NUM_THREADS` where it is set, as
/// for every other command, else one per core.
fn threads() -> Result<usize> {
    Ok(crate::threads::count(None, "RAYON_NUM_THREADS")?
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(2, |n| n.get())))
}

/// Every run on one thread and on many (the threads of [`threads`], at least two); `tick`
/// after each.
pub(crate) fn determinism(quick: bool, tick: &mut dyn FnMut()) -> Result<Vec<Hashes>> {
    let many = threads()?.max(2);
    let one_pool = crate::threads::build(Some(1))?;
    let many_pool = crate::threads::build(Some(many))?;
    let mut out = Vec::new();
    for (source, seconds) in runs(quick) {
        out.push(Hashes {
            run: format!("{source}, {seconds} s"),
            one_thread: run_hash(source, seconds, &one_pool)?,
            threads: many,
            many_threads: run_hash(source, seconds, &many_pool)?,
        });
        tick();
    }
    Ok(out)
}

/// The cloth-N workload stepped for `budget` of wall time on the report's threads, and `cloth-table`
/// for a simulated second (a tenth with `quick`).
pub(crate) fn speed(quick: bool) -> Result<Speed> {
    let threads = threads()?;
    let pool = crate::threads::build(Some(threads))?;
    pool.install(|| {
        let n = 128;
        let mut scene = hooke_scene::workload::cloth(n).build(std::path::Path::new("."))?;
        let springs = scene.simulation.model().springs.len() as f64;
        let budget = Duration::from_secs_f64(if quick { 0.5 } else { 2.0 });
        scene.simulation.step()?;
        let (started, mut steps) = (Instant::now(), 0u64);
        while started.elapsed() < budget {
            crate::interrupt::check(&scene.simulation)?;
            scene.simulation.step()?;
            steps += 1;
        }
        let rate = steps as f64 / started.elapsed().as_secs_f64();
        let seconds = if quick { 0.1 } else { 1.0 };
        let mut table = crate::source::build(
            "cloth-table",
            &Overrides {
                duration: Some(seconds),
                ..Overrides::default()
            },
        )?;
        let started = Instant::now();
        let steps = table.steps;
        crate::driver::advance(&mut table, steps)?;
        Ok(Speed {
            workload: format!("cloth-{n} (docs/benchmarks.md), symplectic Euler"),
            threads,
            steps_per_second: rate,
            spring_updates_per_second: rate * springs,
            cloth_table_wall_per_simulated: started.elapsed().as_secs_f64() / seconds,
        })
    })
}

/// The CPU's name as Linux gives it, and the rest.
pub(crate) fn machine() -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    Machine {
        cpu,
        logical_cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
        spring_kernel: hooke_core::Kernel::detect().to_string(),
        os: std::env::consts::OS.to_string(),
    }
}
