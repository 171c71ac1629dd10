//! `hooke report DIR`: the evidence that the physics is right, run on this machine and
//! written as a static page (`DIR/index.html`, its plots and pictures beside it, every
//! number also in `DIR/report.json`): each integrator's convergence and stability on the
//! single spring against the closed form, closed forms of statics and air, energy over time
//! against the damping's prediction, every built-in scene's still against its golden image
//! with its contacts checked, the course worlds against their reference trajectories,
//! bit-identical runs on one and many threads, and this machine's speed. A check that fails
//! is listed at the top of the page.

mod convergence;
pub mod crossings;
mod drape;
mod energy;
mod folder;
mod machine;
mod page;
mod physics;
pub mod pixels;

pub use physics::{RHO, falling_sheet};
mod plots;
mod references;
mod scenes;
mod worlds;

use crate::Result;
use crate::progress::reporter;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// How much to run.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// Shorter sweeps and runs, the three quickest scenes, each world with its own
    /// integrator only: under half a minute.
    pub quick: bool,
}

/// What a report found.
#[derive(Debug)]
pub struct Outcome {
    /// The page.
    pub page: PathBuf,
    /// Each failed check, said in a line; empty when all passed.
    pub failures: Vec<String>,
}

/// Everything the page shows, as `report.json` holds it.
#[derive(Serialize)]
struct Report {
    hooke_version: &'static str,
    quick: bool,
    failures: Vec<String>,
    machine: machine::Machine,
    convergence: Vec<convergence::Sweep>,
    closed_forms: Vec<physics::Closed>,
    energy_window_seconds: f64,
    energy: Vec<energy::EnergyRun>,
    scenes: Vec<scenes::SceneCheck>,
    worlds: Vec<worlds::WorldRun>,
    /// The drape test (none with `--quick`).
    drape: Option<drape::Drape>,
    determinism: Vec<machine::Hashes>,
    speed: machine::Speed,
    /// Wall seconds each section took here.
    seconds: Vec<(&'static str, f64)>,
}

/// The energy a closed scene loses beyond what damping took, as a share of what it took,
/// with midpoint and RK4 (whose own energy error at the scene's step is far smaller).
const ENERGY_TOLERANCE: f64 = 0.01;

/// Runs every check and writes the page into `dir` (created if missing).
pub fn write(dir: &Path, options: &Options) -> Result<Outcome> {
    // The report's runs ask for interrupts between their steps and stop it in order
    // (leaving the earlier report, or nothing, and its folder unlocked).
    let _polling = crate::interrupt::Polling::start();
    let quick = options.quick;
    let checked = scenes::names(quick);
    // Before anything is written: a report that cannot compare cannot run.
    let references = references::References::find(&checked)?;
    crate::output::check_output_folder(dir, "report")?;
    folder::check(dir, &checked)?;
    crate::output::create_folder(dir, "report")?;
    let _held = crate::output::lock::FolderLock::take(dir, "report")?;
    // Again under the lock: another run may have written the folder meanwhile.
    folder::check(dir, &checked)?;
    let mut files = folder::Pending::default();
    // As many steps as ticks: two convergence sweeps per integrator, the closed forms, the
    // energy runs (one per built-in), the scenes, the worlds, the drape test's runs, the three determinism runs,
    // the speed.
    let total = 2 * hooke_core::Integrator::ALL.len()
        + 1
        + hooke_scene::builtin::BUILTINS.len()
        + checked.len()
        + references::WORLDS.len()
        + drape::ticks(quick)
        + 3
        + 1;
    let total = total as u64;
    let bar = reporter().run("report", total);
    let mut done = 0;
    let mut tick = || {
        done += 1;
        bar.set(done);
    };
    let mut seconds = Vec::new();
    let mut clock = std::time::Instant::now();
    let mut lap = |name: &'static str| {
        seconds.push((name, clock.elapsed().as_secs_f64()));
        clock = std::time::Instant::now();
    };
    let convergence = convergence::sweeps(quick, &mut tick)?;
    lap("convergence");
    let closed_forms = physics::checks()?;
    tick();
    lap("closed forms");
    let energy = energy::runs(quick, &mut tick)?;
    lap("energy");
    let scenes = scenes::checks(quick, &references, &mut files, &mut tick)?;
    lap("scenes");
    let worlds = worlds::runs(quick, &references, &mut tick)?;
    lap("worlds");
    let drape = drape::runs(quick, &mut files, &mut tick)?;
    lap("drape");
    let determinism = machine::determinism(quick, &mut tick)?;
    lap("determinism");
    let speed = machine::speed(quick)?;
    tick();
    lap("speed");
    bar.finish();
    let mut report = Report {
        hooke_version: env!("CARGO_PKG_VERSION"),
        quick,
        failures: Vec::new(),
        machine: machine::machine(),
        convergence,
        closed_forms,
        energy_window_seconds: energy::window(quick),
        energy,
        scenes,
        worlds,
        drape,
        determinism,
        speed,
        seconds,
    };
    report.failures = failures(&report);
    page::write(&mut files, &report)?;
    files.commit(dir, &checked)?;
    Ok(Outcome {
        page: dir.join(folder::PAGE),
        failures: report.failures,
    })
}

/// Whether `x` is a number no larger than `tolerance` either way (NaN is not).
fn within(x: f64, tolerance: f64) -> bool {
    x.abs() <= tolerance
}

/// Each check that failed, in a line.
fn failures(r: &Report) -> Vec<String> {
    let mut out = Vec::new();
    for s in &r.convergence {
        if !s.order_agrees() {
            out.push(format!(
                "convergence: {} fits order {:.2} on the single spring, expected {} ± {}",
                s.integrator,
                s.slope,
                s.expected,
                convergence::SLOPE_TOLERANCE
            ));
        }
        if !s.stability_agrees() {
            out.push(format!(
                "stability: {} went unstable at dt = {:.4e} s, theory says {:.4e} s",
                s.integrator, s.measured_limit, s.theory_limit
            ));
        }
    }
    for c in &r.closed_forms {
        if !c.passed() {
            out.push(format!(
                "{}: measured {:.6} {}, {} = {:.6} {} (tolerance {:.1e})",
                c.what, c.measured, c.unit, c.formula, c.expected, c.unit, c.tolerance
            ));
        }
    }
    for (name, make) in hooke_scene::builtin::BUILTINS {
        let own = make().simulation.integrator.0.to_string();
        for e in r.energy.iter().filter(|e| e.scene == name) {
            if e.integrator == own && e.diverged {
                out.push(format!(
                    "energy: {name} diverged with its own integrator {own}"
                ));
            }
            // The higher-order schemes' own energy error is far below the damping's take:
            // there the two must agree.
            let accurate = e.integrator == "rk4" || e.integrator == "midpoint";
            if e.closed
                && accurate
                && !e.diverged
                && !within(
                    e.change - e.predicted_change,
                    ENERGY_TOLERANCE * e.predicted_change.abs().max(1e-9),
                )
            {
                out.push(format!(
                    "energy: {name} ({}) changed by {:.4e} J where its damping took {:.4e} J",
                    e.integrator, e.change, -e.predicted_change
                ));
            }
        }
    }
    for s in &r.scenes {
        if !s.matches_golden() {
            out.push(format!(
                "scenes: {}'s still differs from its golden image in {} of {} pixels (at most {:.1} % may)",
                s.name,
                s.differing_pixels,
                s.pixels,
                100.0 * pixels::MISMATCH_FRACTION
            ));
        }
        if s.crossings() > 0 {
            out.push(format!(
                "contacts: {} has {} cloth–collider and {} cloth–cloth crossings over {} frames",
                s.name, s.collider_crossings, s.cloth_crossings, s.frames
            ));
        }
    }
    for w in r.worlds.iter().filter(|w| w.own && !w.matches_reference()) {
        match w.max_difference {
            Some(d) => out.push(format!(
                "worlds: {} with {} differs from its reference by {d:.3e} m",
                w.world, w.integrator
            )),
            None => out.push(format!(
                "worlds: {} diverged with {}",
                w.world, w.integrator
            )),
        }
    }
    if let Some(d) = &r.drape {
        out.extend(drape::failures(d));
    }
    for h in &r.determinism {
        if !h.agree() {
            out.push(format!(
                "determinism: {} hashes {} on 1 thread and {} on {}",
                h.run, h.one_thread, h.many_threads, h.threads
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A report whose one check failed: what a build with gravity 9.71 gives for the
    /// single spring's statics.
    fn failing() -> Report {
        Report {
            hooke_version: "test",
            quick: true,
            failures: Vec::new(),
            machine: machine::machine(),
            convergence: Vec::new(),
            closed_forms: vec![physics::Closed {
                what: "single-spring: height at rest".into(),
                formula: "anchor − rest − m g / k".into(),
                expected: 0.9019,
                measured: 0.9029,
                tolerance: 2e-4,
                unit: "m".into(),
            }],
            energy_window_seconds: 0.05,
            energy: Vec::new(),
            scenes: Vec::new(),
            worlds: Vec::new(),
            drape: None,
            determinism: Vec::new(),
            speed: machine::Speed {
                workload: "none".into(),
                threads: 1,
                steps_per_second: 0.0,
                spring_updates_per_second: 0.0,
                cloth_table_wall_per_simulated: 0.0,
            },
            seconds: Vec::new(),
        }
    }

    #[test]
    fn a_failed_check_is_said_at_the_top_of_the_page_in_red() {
        let mut report = failing();
        report.failures = failures(&report);
        assert_eq!(report.failures.len(), 1, "{:?}", report.failures);
        assert!(report.failures[0].contains("height at rest"));
        let dir = std::env::temp_dir().join(format!("hooke-report-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut files = folder::Pending::default();
        page::write(&mut files, &report).unwrap();
        files.commit(&dir, &[]).unwrap();
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        let banner = html.find("banner fail").expect("a red banner");
        let first_section = html.find("<h2").unwrap();
        assert!(
            banner < first_section,
            "the failures come before the sections"
        );
        assert!(html[banner..first_section].contains("height at rest"));
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(json["failures"].as_array().unwrap().len(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
