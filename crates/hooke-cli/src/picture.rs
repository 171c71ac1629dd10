//! `hooke render` and `hooke demo`.

use crate::RenderArgs;
use crate::image_out::{View, write_gif, write_png};
use crate::run::drive;
use crate::source;
use anyhow::{Context, Result};
use hooke_cli::stills::{still_scene, still_view};
use hooke_scene::builtin::BUILTINS;
use hooke_scene::{Overrides, Scene};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Runs `scene` for `steps` steps (frames ignored), stopping on divergence.
fn advance(scene: &mut Scene, steps: u64) -> Result<()> {
    scene.steps = steps;
    scene.every = steps.max(1);
    drive(scene, |_, _| Ok(()))
}

pub fn render(args: &RenderArgs) -> Result<ExitCode> {
    let mut scene = source::build(&args.scene, &args.setup.overrides())?;
    let dt = scene.simulation.dt();
    let steps = match args.at {
        Some(t) if t.is_finite() && t >= 0.0 => (t / dt).round() as u64,
        Some(t) => anyhow::bail!("--at: expected a time in seconds >= 0, found {t}"),
        None => scene.steps,
    };
    advance(&mut scene, steps)?;
    let camera = args.view.camera(&scene);
    write_png(&args.output, &args.view.pixels(&scene, &camera))?;
    eprintln!(
        "{}: t = {} s -> {}",
        scene.spec.name,
        scene.simulation.time(),
        args.output.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// The scene animated in `demo`, and its frame interval in seconds.
const ANIMATED: (&str, f64) = ("hanging-cloth", 0.1);

pub fn demo(out: &Path, view: &View) -> Result<ExitCode> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output folder {}", out.display()))?;
    let mut written: Vec<PathBuf> = Vec::new();
    for (k, (name, _)) in BUILTINS.iter().enumerate() {
        let started = Instant::now();
        let scene = still_scene(name)?;
        let simulated = started.elapsed();
        let view = still_view(name, view);
        let camera = view.camera(&scene);
        let path = out.join(format!("{}-{name}.png", k + 1));
        write_png(&path, &view.pixels(&scene, &camera))?;
        eprintln!(
            "{name:<14} {} s simulated in {:.2} s, still rendered in {:.2} s -> {}",
            scene.simulation.time(),
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

/// Re-runs a scene and writes a GIF of it, framed like its final still.
fn animate(
    name: &str,
    camera: &hooke_render::Camera,
    interval: f64,
    out: &Path,
    view: &View,
) -> Result<PathBuf> {
    let mut scene = source::build(name, &Overrides::default())?;
    scene.every = ((interval / scene.simulation.dt()).round() as u64).max(1);
    let small = View {
        size: (view.size.0 / 2, view.size.1 / 2),
        supersample: 1,
        ..view.clone()
    };
    let mut frames = Vec::new();
    drive(&mut scene, |_, scene| {
        frames.push(small.pixels(scene, camera));
        Ok(())
    })?;
    let path = out.join(format!("{name}.gif"));
    let count = frames.len();
    write_gif(&path, frames, (interval * 1000.0).round() as u32)?;
    eprintln!(
        "{name:<14} animation of {count} frames -> {}",
        path.display()
    );
    Ok(path)
}

/// Writes frames of a run as numbered PNGs and optionally a GIF.
pub struct FrameSink {
    dir: Option<PathBuf>,
    gif: Option<PathBuf>,
    view: View,
    camera: Option<hooke_render::Camera>,
    frames: Vec<image::RgbaImage>,
    frame_ms: u32,
}

impl FrameSink {
    pub fn new(
        dir: Option<PathBuf>,
        gif: Option<PathBuf>,
        view: View,
        frame_seconds: f64,
    ) -> Result<Option<Self>> {
        if dir.is_none() && gif.is_none() {
            return Ok(None);
        }
        if let Some(d) = &dir {
            std::fs::create_dir_all(d)
                .with_context(|| format!("cannot create frame folder {}", d.display()))?;
        }
        let frame_ms = (frame_seconds * 1000.0).round().clamp(10.0, 10_000.0) as u32;
        Ok(Some(Self {
            dir,
            gif,
            view,
            camera: None,
            frames: Vec::new(),
            frame_ms,
        }))
    }

    /// Draws one frame; the camera is fixed by the first frame, with room for motion.
    pub fn frame(&mut self, frame: u64, scene: &Scene) -> Result<()> {
        let camera = *self.camera.get_or_insert_with(|| {
            let mut c = self.view.camera(scene);
            c.distance *= 1.3;
            c
        });
        let image = self.view.pixels(scene, &camera);
        if let Some(d) = &self.dir {
            write_png(&d.join(format!("frame-{frame:05}.png")), &image)?;
        }
        if self.gif.is_some() {
            self.frames.push(image);
        }
        Ok(())
    }

    pub fn finish(self) -> Result<()> {
        if let Some(g) = &self.gif {
            write_gif(g, self.frames, self.frame_ms)?;
        }
        Ok(())
    }
}
