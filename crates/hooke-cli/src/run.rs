//! `hooke run`, `hooke check` and `hooke convert`.

use crate::{RunArgs, SetupArgs};
use anyhow::{Context, Result, bail};
use hooke::export::Target;
use hooke::frames::Frames;
use hooke::interrupt::{self, is_interrupt};
use hooke::output::claims::Claims;
use hooke::output::{check_output_file, check_output_folder};
use hooke::trajectory::TrajectoryWriter;
use hooke::{Sink, record, source};
use hooke_core::Num;
use hooke_core::{Integrator, StabilityEstimate, Summary};
use hooke_scene::{Overrides, Scene};
use std::path::Path;
use std::process::ExitCode;

fn is_divergence(e: &hooke::Error) -> bool {
    matches!(e, hooke::Error::Diverged { .. })
}

/// Warns on stderr when the scene's step exceeds the estimated stable step.
fn warn_if_unstable(scene: &Scene) -> StabilityEstimate {
    let sim = &scene.simulation;
    let estimate = sim.stability();
    let limit = estimate.max_dt(sim.integrator());
    if sim.dt() > limit {
        eprintln!(
            "warning: dt = {} s exceeds the estimated stable step of {} ({limit:.3e} s, ω_max = {:.4e} rad/s); the run may diverge",
            Num(sim.dt()),
            sim.integrator(),
            estimate.omega_max
        );
    }
    estimate
}

/// One thin collider against the fastest motion the scene can reach.
struct Tunnelling {
    collider: String,
    thickness: f64,
    speed: f64,
    drop: f64,
    per_step: f64,
    /// The largest step that keeps a step's travel within half the thickness.
    safe_dt: f64,
}

/// For every collider with a finite thickness: how far the fastest particle moves in one
/// step. The speed is the larger of the fastest particle now and a free fall from the
/// highest particle to the ground (or the lowest particle): what a falling cloth reaches.
fn tunnelling(scene: &Scene) -> Vec<Tunnelling> {
    let sim = &scene.simulation;
    let model = sim.model();
    let (speed, drop) = fastest(scene);
    model
        .colliders
        .iter()
        .filter_map(|slot| {
            // A collider without thickness (an open sheet) is held by the crossing test,
            // not by depth: nothing to tunnel through.
            let thickness = slot.shape.thickness().filter(|t| *t > 0.0)?;
            Some(Tunnelling {
                collider: slot.shape.name(),
                thickness,
                speed,
                drop,
                per_step: speed * sim.dt(),
                safe_dt: if speed > 0.0 {
                    0.5 * thickness / speed
                } else {
                    f64::INFINITY
                },
            })
        })
        .collect()
}

impl Tunnelling {
    fn risky(&self) -> bool {
        self.per_step > 0.5 * self.thickness
    }

    fn describe(&self, dt: f64) -> String {
        format!(
            "{} is {:.1} mm thick at its thinnest; at {:.2} m/s (a fall of {:.2} m) a particle moves \
             {:.1} mm per step of {} s",
            self.collider,
            self.thickness * 1e3,
            self.speed,
            self.drop,
            self.per_step * 1e3,
            Num(dt)
        )
    }
}

/// The fastest a particle can move, m/s: the larger of the fastest now and a free fall from
/// the highest particle to the ground (or the lowest particle); and that fall's height.
fn fastest(scene: &Scene) -> (f64, f64) {
    let sim = &scene.simulation;
    let p = sim.particles();
    let top = p.x.iter().map(|x| x.y).fold(f64::NEG_INFINITY, f64::max);
    let mut bottom = p.x.iter().map(|x| x.y).fold(f64::INFINITY, f64::min);
    for c in &scene.colliders {
        if let hooke_scene::ColliderGeometry::Ground(h) = c {
            bottom = bottom.min(*h);
        }
    }
    let drop = (top - bottom).max(0.0);
    let fall = (2.0 * sim.model().gravity.norm() * drop).sqrt();
    let now = p.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    (fall.max(now), drop)
}

/// Below this explicit step (a tenth of a 60 Hz frame) `hooke check` recommends block
/// descent for a scene with contact surfaces.
const TINY_STEP: f64 = 1.0 / 600.0;

/// The recommendation of `hooke check` for a scene with contact surfaces stepped by an
/// explicit integrator whose stable step (or tunnelling-safe step) is tiny: block descent at
/// a display frame.
fn large_step_advice(scene: &Scene, estimate: &StabilityEstimate) -> Option<String> {
    let sim = &scene.simulation;
    if sim.integrator() == Integrator::Vbd || !scene.bodies.iter().any(|b| b.thickness > 0.0) {
        return None;
    }
    // The stable explicit step, and the step that keeps two layers closing at the fastest
    // speed from covering a thickness (the explicit contact phase's condition).
    let (speed, _) = fastest(scene);
    let layers = scene
        .bodies
        .iter()
        .filter(|b| b.thickness > 0.0 && speed > 0.0)
        .map(|b| b.thickness / (2.0 * speed))
        .fold(f64::INFINITY, f64::min);
    let limit = estimate.max_dt(Integrator::Symplectic).min(layers);
    if limit >= TINY_STEP {
        return None;
    }
    Some(format!(
        "recommendation: explicit steps here must stay below {limit:.3e} s ({:.0} steps per \
         simulated second); `--integrator vbd --dt 0.016666666666666666` takes one implicit \
         step per 60 Hz frame with no crossing (docs/physics.md §4.1)",
        1.0 / limit
    ))
}

/// For each body with a contact thickness: a message when two of its layers, closing at
/// twice the fastest speed, can cover the thickness in one step, so that a proximity is not
/// seen before a crossing (`docs/physics.md` §3.3), with the largest safe step.
fn thin_surfaces(scene: &Scene) -> Vec<String> {
    let dt = scene.simulation.dt();
    let (speed, _) = fastest(scene);
    scene
        .bodies
        .iter()
        .filter(|b| b.thickness > 0.0 && 2.0 * speed * dt > b.thickness)
        .map(|b| {
            format!(
                "body '{}': two layers closing at {:.2} m/s move {:.1} mm per step of {} s, more \
                 than its contact thickness of {:.1} mm, so they can cross unseen; use dt below \
                 {:.3e} s or a larger thickness",
                b.name,
                2.0 * speed,
                2.0 * speed * dt * 1e3,
                Num(dt),
                b.thickness * 1e3,
                b.thickness / (2.0 * speed)
            )
        })
        .collect()
}

/// Warns on stderr about thin colliders a particle can cross in one step. Block descent
/// bounds every update so that nothing crosses whatever the step: no warning for it.
fn warn_if_tunnelling(scene: &Scene) {
    if scene.simulation.integrator() == Integrator::Vbd {
        return;
    }
    let dt = scene.simulation.dt();
    for t in tunnelling(scene).iter().filter(|t| t.risky()) {
        eprintln!(
            "warning: {}: more than half its thickness, so a particle can pass through or be \
             pushed out the far side (tunnelling); use dt below {:.3e} s",
            t.describe(dt),
            t.safe_dt
        );
    }
    for message in thin_surfaces(scene) {
        eprintln!("warning: {message}");
    }
}

pub fn run(args: &RunArgs) -> Result<ExitCode> {
    // Every output is checked before the scene is built and run.
    if let Some(path) = &args.trajectory {
        check_output_file(path, "--trajectory", &[])?;
    }
    if let Some(path) = &args.gif {
        check_output_file(path, "--gif", &["gif"])?;
    }
    if let Some(dir) = &args.frames {
        check_output_folder(dir, "--frames")?;
    }
    let export_target = args
        .export
        .as_deref()
        .map(|path| Target::new(path, args.format, args.body.as_deref()))
        .transpose()?;
    let overrides = Overrides {
        every: args.every,
        ..args.setup.overrides()?
    };
    let source = source::prepare(source::read(&args.scene)?, &args.scene, &overrides)?;
    // No output may replace an input or another output.
    let mut claims = Claims::with_inputs(source.inputs());
    if let Some(path) = &args.trajectory {
        claims.file("--trajectory", path);
    }
    if let Some(path) = &args.gif {
        claims.file("--gif", path);
    }
    if let Some(dir) = &args.frames {
        claims.frames("--frames", dir, "png");
    }
    if let Some(target) = &export_target {
        target.claim(&mut claims);
    }
    if args.summary {
        claims.file("--summary", Path::new("-"));
    }
    claims.check()?;
    let mut scene = source::build_prepared(source, &args.scene)?;
    warn_if_unstable(&scene);
    warn_if_tunnelling(&scene);
    let every = scene.every;
    let dt = scene.simulation.dt();
    if args.summary {
        println!(
            "{:>6} {:>10} {:>13} {:>13} {:>26} {:>26} {:>10} {:>11}",
            "frame",
            "time",
            "kinetic",
            "potential",
            "bbox min",
            "bbox max",
            "max speed",
            "max depth"
        );
    }
    // The outputs in the order they are finished: the trajectory, the pictures, the export.
    let mut sinks: Vec<Box<dyn Sink>> = Vec::new();
    if let Some(path) = &args.trajectory {
        sinks.push(Box::new(TrajectoryWriter::create(path)?));
    }
    if let Some(frames) = Frames::new(
        args.frames.clone(),
        args.gif.clone(),
        args.view.view(),
        every as f64 * dt,
    )? {
        sinks.push(Box::new(frames));
    }
    let exporting = export_target.is_some();
    if let Some(target) = &export_target {
        sinks.push(hooke::export::create(target, &scene)?);
    }
    let result = record(&mut scene, sinks, |frame, scene| {
        if args.summary {
            let sim = &scene.simulation;
            // docs/physics.md §6: the time of frame f is (f K) dt computed as one product.
            let time = (frame * every) as f64 * dt;
            let s = Summary::of(sim.model(), sim.particles());
            let v = |v: hooke_core::Vec3| format!("({:.3}, {:.3}, {:.3})", v.x, v.y, v.z);
            println!(
                "{frame:>6} {time:>10.4} {:>13.6e} {:>13.6e} {:>26} {:>26} {:>10.4} {:>11.3e}",
                s.kinetic,
                s.potential,
                v(s.min),
                v(s.max),
                s.max_speed,
                s.max_penetration
            );
        }
        Ok(())
    });
    // After a divergence or Ctrl-C the frames already written are complete and were kept.
    let result = result.map(|recording| {
        if exporting && let Some(written) = recording.written.last() {
            eprintln!("export: {written}");
        }
        recording.stopped
    });
    let result = match result {
        Ok(None) => Ok(()),
        Ok(Some(e)) | Err(e) => Err(e),
    };
    if let Err(e) = &result
        && is_interrupt(e)
    {
        eprintln!("{e}: stopped; files end at the last complete frame");
        if let Some(path) = &args.trajectory {
            eprintln!("trajectory: {}", path.display());
        }
        return Ok(ExitCode::from(interrupt::EXIT_INTERRUPTED));
    }
    if let Err(e) = result {
        // Stiff springs are the usual cause; a strong wind is the other one a scene sets.
        let wind = scene
            .simulation
            .model()
            .air
            .as_ref()
            .map(|air| air.wind.norm() + air.gust.as_ref().map_or(0.0, |g| g.amplitude.norm()));
        return Err(match wind {
            Some(w) if is_divergence(&e) && w > 0.0 => e.context(format!(
                "the scene's air blows at up to {w:.1} m/s: a strong wind needs a small dt as \
                 much as stiff springs do"
            )),
            _ => e,
        }
        .into());
    }
    let sim = &scene.simulation;
    eprintln!(
        "{}: {} steps of {} s with {} ({} s simulated), {} particles, {} springs",
        scene.spec.name,
        sim.steps(),
        Num(sim.dt()),
        sim.integrator(),
        Num(sim.time()),
        sim.particles().len(),
        sim.model().springs.len()
    );
    if let Some(path) = &args.trajectory {
        let frames = scene.steps / every + 1;
        eprintln!(
            "trajectory: {} ({frames} frame{})",
            path.display(),
            if frames == 1 { "" } else { "s" }
        );
    }
    Ok(ExitCode::SUCCESS)
}

pub fn check(arg: &str, setup: &SetupArgs) -> Result<ExitCode> {
    let scene = source::build(arg, &setup.overrides()?)?;
    let sim = &scene.simulation;
    let estimate = warn_if_unstable(&scene);
    println!(
        "scene {}: {} particles, {} springs",
        scene.spec.name,
        sim.particles().len(),
        sim.model().springs.len()
    );
    println!(
        "highest angular frequency ω_max ≈ {:.4e} rad/s (power iteration on M⁻¹K)",
        estimate.omega_max
    );
    println!(
        "scene step: dt = {} s with {}",
        Num(sim.dt()),
        sim.integrator()
    );
    for integrator in Integrator::ALL {
        let limit = estimate.max_dt(integrator);
        let mark = if integrator == sim.integrator() {
            "  <- scene"
        } else {
            ""
        };
        let line = match integrator {
            _ if !limit.is_finite() => {
                "stable for any dt (accuracy still wants small steps)".to_string()
            }
            // Their amplification factor exceeds 1 for every undamped mode at every dt.
            Integrator::Euler | Integrator::Midpoint => format!(
                "grows undamped oscillation at any dt; with enough damping, dt < {limit:.3e} s"
            ),
            _ => format!("stable for dt < {limit:.3e} s"),
        };
        println!("  {:<11} {line}{mark}", integrator.name());
    }
    let dt = sim.dt();
    if let Some(advice) = large_step_advice(&scene, &estimate) {
        println!("{advice}");
    }
    if sim.integrator() == Integrator::Vbd {
        println!(
            "contacts: vbd bounds every update, so no surface crosses a collider or another \
             surface at any dt (docs/physics.md §4.1)"
        );
        return Ok(ExitCode::SUCCESS);
    }
    for t in tunnelling(&scene) {
        if t.risky() {
            println!(
                "warning: tunnelling: {}; keep dt below {:.3e} s",
                t.describe(dt),
                t.safe_dt
            );
        } else {
            println!(
                "thin collider: {}: no tunnelling below dt = {:.3e} s",
                t.describe(dt),
                t.safe_dt
            );
        }
    }
    for message in thin_surfaces(&scene) {
        println!("warning: tunnelling: {message}");
    }
    Ok(ExitCode::SUCCESS)
}

pub fn convert(input: &Path, output: &Path) -> Result<ExitCode> {
    let streamed = check_output_file(output, "convert", &["toml", "w"])?.is_stream();
    let mut claims = Claims::default();
    claims.input("the file converted", input);
    claims.file("convert", output);
    claims.check()?;
    let ext = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_string()
    };
    // A stream (`-`, a device, a FIFO) takes the other format than the input's.
    let to = match (streamed, ext(input).as_str()) {
        (true, "w") => "toml".to_string(),
        (true, "toml") => "w".to_string(),
        _ => ext(output),
    };
    let text = match (ext(input).as_str(), to.as_str()) {
        ("w", "toml") => {
            let world = hooke_scene::world::load_world(input)?;
            let name = input
                .file_stem()
                .map_or("world".into(), |s| s.to_string_lossy().into_owned());
            let spec = world
                .to_scene(&name)
                .with_context(|| format!("{}", input.display()))?;
            hooke_scene::to_toml(&spec)
        }
        ("toml", "w") => {
            let spec = hooke_scene::load_scene(input)?;
            let world = hooke_scene::world::World::from_scene(&spec)
                .with_context(|| format!("{} cannot be saved as a jello world", input.display()))?;
            world.to_text()
        }
        (a, b) => bail!(
            "cannot convert .{a} to .{b}: expected a .w world and a .toml scene, one each way"
        ),
    };
    crate::output::write_atomic(output, text.as_bytes())?;
    eprintln!("wrote {}", output.display());
    Ok(ExitCode::SUCCESS)
}
