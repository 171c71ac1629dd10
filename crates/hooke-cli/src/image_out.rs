//! Rendering scenes to PNG stills and GIF animations, written atomically.

use crate::draw::{Style, draw, frame_camera};
use crate::output::write_atomic;
use anyhow::{Context, Result};
use hooke_render::{Camera, RenderOptions, render};
use hooke_scene::Scene;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, ImageFormat, RgbaImage};
use std::io::Cursor;
use std::path::Path;

/// Camera placement options shared by the commands that draw.
#[derive(clap::Args, Clone, Debug)]
pub struct View {
    /// Image size as WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600", value_parser = parse_size)]
    pub size: (u32, u32),
    /// What to draw.
    #[arg(long, value_enum, default_value_t = Style::Solid)]
    pub style: Style,
    /// Camera rotation about the vertical, degrees.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub yaw: f64,
    /// Camera elevation, degrees.
    #[arg(long, default_value_t = 22.0, allow_negative_numbers = true)]
    pub pitch: f64,
    /// Multiply the framing distance (less than 1 zooms in).
    #[arg(long, default_value_t = 1.0)]
    pub zoom: f64,
    /// Samples per pixel along each axis (2 = 4× anti-aliasing, 1 = off).
    #[arg(long, default_value_t = 2)]
    pub supersample: u32,
}

/// Parses `WIDTHxHEIGHT`, each from 8 to 8192 pixels.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once('x')
        .ok_or_else(|| format!("expected WIDTHxHEIGHT such as 800x600, found '{s}'"))?;
    let parse = |v: &str| v.parse::<u32>().ok().filter(|n| (8..=8192).contains(n));
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!(
            "expected WIDTHxHEIGHT with each from 8 to 8192, found '{s}'"
        )),
    }
}

impl View {
    /// The camera for the scene's current state.
    pub fn camera(&self, scene: &Scene) -> Camera {
        let mut camera = frame_camera(scene, self.yaw, self.pitch);
        camera.distance *= self.zoom;
        camera
    }

    /// Renders the scene's current state to RGBA pixels.
    pub fn pixels(&self, scene: &Scene, camera: &Camera) -> RgbaImage {
        let options = RenderOptions {
            width: self.size.0,
            height: self.size.1,
            supersample: self.supersample.clamp(1, 4),
            ..RenderOptions::default()
        };
        let pixels = render(&draw(scene, self.style), camera, &options);
        RgbaImage::from_raw(self.size.0, self.size.1, pixels)
            .expect("renderer returns width × height pixels")
    }
}

/// Encodes and writes a PNG atomically.
pub fn write_png(path: &Path, image: &RgbaImage) -> Result<()> {
    let mut bytes = Vec::new();
    image
        .write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    write_atomic(path, &bytes)
}

/// Encodes frames as a looping GIF and writes it atomically.
pub fn write_gif(path: &Path, frames: Vec<RgbaImage>, frame_ms: u32) -> Result<()> {
    let mut bytes = Vec::new();
    {
        let mut encoder = GifEncoder::new_with_speed(&mut bytes, 10);
        encoder.set_repeat(Repeat::Infinite).context("gif")?;
        encoder
            .encode_frames(
                frames
                    .into_iter()
                    .map(|f| Frame::from_parts(f, 0, 0, Delay::from_numer_denom_ms(frame_ms, 1))),
            )
            .with_context(|| format!("cannot encode {}", path.display()))?;
    }
    write_atomic(path, &bytes)
}
