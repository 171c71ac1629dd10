//! `hooke bench render`: the rasterizer's frame time, with and without shadows, and the
//! PNG encoder's.

use super::cloth::workload;
use super::{median, threads};
use crate::draw::{DEFAULT_YAW_PITCH, Style, draw, frame_camera};
use crate::source;
use anyhow::{Context, Result};
use hooke_core::Integrator;
use hooke_render::{RenderOptions, Renderer};
use hooke_scene::{Overrides, Scene};
use image::{ImageFormat, RgbaImage};
use serde::Serialize;
use std::io::Cursor;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

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

pub(super) fn renders(
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
