//! `hooke run`: simulate a scene and write what was asked (trajectory, frames, GIF, export).

use crate::RunArgs;
use crate::advice::warn_if_other_large_step;
use crate::risks::{warn_if_tunnelling, warn_if_unstable};
use anyhow::Result;
use hooke::export::Target;
use hooke::frames::Frames;
use hooke::interrupt::{self, is_interrupt};
use hooke::output::claims::Claims;
use hooke::output::{check_output_file, check_output_folder};
use hooke::quantity::ColorBy;
use hooke::trajectory::TrajectoryWriter;
use hooke::{Sink, record, source};
use hooke_core::Num;
use hooke_core::Summary;
use hooke_scene::Overrides;
use std::path::Path;
use std::process::ExitCode;

fn is_divergence(e: &hooke::Error) -> bool {
    matches!(e, hooke::Error::Diverged { .. })
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
    let mut view = args.view.view();
    let animated = args.gif.is_some() || args.frames.is_some();
    if animated && view.color != ColorBy::None && view.range.is_none() {
        eprintln!(
            "--color {}: a first pass over the run fixes the colour range of every frame \
             (--range LO,HI skips it)",
            view.color.title()
        );
        let first = source::build(&args.scene, &overrides)?;
        let range = hooke::frames::animation_range(first, view.color);
        eprintln!(
            "--color: {} from {} to {}",
            view.color.title(),
            hooke_render::short(range.0),
            hooke_render::short(range.1)
        );
        view.range = Some(range);
    }
    let mut scene = source::build_prepared(source, &args.scene)?;
    // A cache per body is named after the bodies, known only now.
    if let Some(target) = &export_target {
        target.claim_bodies(&scene, &mut claims)?;
        claims.check()?;
    }
    let estimate = warn_if_unstable(&scene);
    warn_if_tunnelling(&scene);
    warn_if_other_large_step(&scene, &estimate);
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
        view,
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
            let time = hooke::driver::frame_time(scene, frame);
            let s = Summary::of(sim.model(), sim.particles());
            // `x + 0.0` is `x` but for -0, which becomes 0: no "-0.000000e0" in the table.
            let z = |x: f64| x + 0.0;
            let v = |v: hooke_core::Vec3| format!("({:.3}, {:.3}, {:.3})", z(v.x), z(v.y), z(v.z));
            println!(
                "{frame:>6} {time:>10.4} {:>13.6e} {:>13.6e} {:>26} {:>26} {:>10.4} {:>11.3e}",
                z(s.kinetic),
                z(s.potential),
                v(s.min),
                v(s.max),
                z(s.max_speed),
                z(s.max_penetration)
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
        hooke_core::Approx(sim.time()),
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
