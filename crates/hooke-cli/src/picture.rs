//! `hooke render` and `hooke demo`.

use crate::RenderArgs;
use anyhow::{Context, Result};
use hooke::driver::{advance, drive, steps_to};
use hooke::image_out::{GifWriter, View, write_png, write_png_named};
use hooke::output::{check_output_file, check_output_folder};
use hooke::source;
use hooke::stills::{still_scene, still_view};
use hooke_core::Num;
use hooke_scene::Overrides;
use hooke_scene::builtin::BUILTINS;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Runs from here on say how many steps they take before starting.
const ANNOUNCE_STEPS: u64 = 1_000_000;

pub fn render(args: &RenderArgs) -> Result<ExitCode> {
    check_output_file(&args.output, "-o", &["png"])?;
    let source = source::prepare(
        source::read(&args.scene)?,
        &args.scene,
        &args.setup.overrides()?,
    )?;
    let mut claims = hooke::output::claims::Claims::with_inputs(source.inputs());
    claims.file("-o", &args.output);
    claims.check()?;
    let mut scene = source::build_prepared(source, &args.scene)?;
    let dt = scene.simulation.dt();
    let steps = steps_to(&scene, args.at)?;
    if steps >= ANNOUNCE_STEPS {
        eprintln!(
            "{}: t = {} s is {steps} steps of {} s (Ctrl-C stops)",
            scene.spec.name,
            hooke_core::Approx(steps as f64 * dt),
            Num(dt)
        );
    }
    advance(&mut scene, steps)?;
    let view = args.view.view();
    let camera = view.camera(&scene);
    write_png(&args.output, &view.pixels(&scene, &camera))?;
    eprintln!(
        "{}: t = {} s -> {}",
        scene.spec.name,
        hooke_core::Approx(scene.simulation.time()),
        args.output.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// The scene animated in `demo`, and its frame interval in seconds.
const ANIMATED: (&str, f64) = ("hanging-cloth", 0.1);

pub fn demo(out: &Path, view: &View) -> Result<ExitCode> {
    check_output_folder(out, "--out")?;
    std::fs::create_dir_all(out)
        .with_context(|| format!("--out {}: cannot create the folder", out.display()))?;
    // Two demos writing one folder would mix their stills.
    let _held = hooke::output::lock::FolderLock::take(out, "--out")?;
    // Each scene's run asks for interrupts; one arriving while the next scene is built is
    // answered at its first step, after the stills written so far.
    let _polling = hooke::interrupt::Polling::start();
    // Every name the demo writes, checked before the first scene runs.
    for (k, (name, _)) in BUILTINS.iter().enumerate() {
        hooke::output::check_named(&out.join(still_name(k, name)), "--out")?;
    }
    hooke::output::check_named(&out.join(animation_name(ANIMATED.0)), "--out")?;
    let mut written: Vec<PathBuf> = Vec::new();
    for (k, (name, _)) in BUILTINS.iter().enumerate() {
        let started = Instant::now();
        let scene = still_scene(name)?;
        let simulated = started.elapsed();
        let view = still_view(name, view);
        let camera = view.camera(&scene);
        let path = out.join(still_name(k, name));
        write_png_named(&path, "--out", &view.pixels(&scene, &camera))?;
        eprintln!(
            "{name:<14} {} s simulated in {:.2} s, still rendered in {:.2} s -> {}",
            hooke_core::Approx(scene.simulation.time()),
            simulated.as_secs_f64(),
            (started.elapsed() - simulated).as_secs_f64(),
            path.display()
        );
        written.push(path);
        if *name == ANIMATED.0 {
            written.push(animate(name, &camera, ANIMATED.1, out, &view)?);
        }
    }
    println!("wrote {} files to {}:", written.len(), out.display());
    for p in &written {
        println!("  {}", p.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// The demo's still of built-in scene number `k`.
fn still_name(k: usize, name: &str) -> String {
    format!("{}-{name}.png", k + 1)
}

/// The demo's animation of scene `name`.
fn animation_name(name: &str) -> String {
    format!("{name}.gif")
}

/// Re-runs a scene and writes a GIF of it, framed like its final still.
fn animate(
    name: &str,
    camera: &hooke_render::Camera,
    interval: f64,
    out: &Path,
    view: &View,
) -> Result<PathBuf> {
    let mut scene = source::build(name, &Overrides::default())?;
    scene.every = hooke::driver::steps_for(&scene, interval).max(1);
    let range = match view.range {
        None if view.color != hooke::quantity::ColorBy::None => {
            let mut first = source::build(name, &Overrides::default())?;
            first.every = scene.every;
            Some(hooke::frames::animation_range(first, view.color))
        }
        range => range,
    };
    let small = View {
        size: (view.size.0 / 2, view.size.1 / 2),
        supersample: 1,
        range,
        ..view.clone()
    };
    let path = out.join(animation_name(name));
    let mut gif = GifWriter::create_named(&path, "--out", small.size, interval * 1000.0)?;
    let result = drive(&mut scene, |_, scene| {
        gif.frame(small.pixels(scene, camera))
    });
    let count = gif.frames();
    // Interrupted, the animation still ends at its last whole frame, as a run's GIF does.
    if result.is_ok() || result.as_ref().is_err_and(hooke::interrupt::is_interrupt) {
        gif.finish()?;
    }
    result?;
    eprintln!(
        "{name:<14} animation of {count} frames -> {}",
        path.display()
    );
    Ok(path)
}
