//! Rendering scenes to PNG stills and GIF animations, written atomically; a GIF is encoded
//! frame by frame as a run produces them, so its memory does not grow with its length.

use crate::draw::{DEFAULT_YAW_PITCH, Style, draw, frame_camera};
use crate::output::{OutputFile, write_atomic};
use anyhow::{Context, Result};
use hooke_render::{Camera, RenderOptions, render};
use hooke_scene::Scene;
use image::{ImageFormat, RgbaImage};
use std::io::Cursor;
use std::path::{Path, PathBuf};

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
    #[arg(long, default_value_t = DEFAULT_YAW_PITCH.0, allow_negative_numbers = true, value_parser = parse_angle)]
    pub yaw: f64,
    /// Camera elevation, degrees, from -89 to 89.
    #[arg(long, default_value_t = DEFAULT_YAW_PITCH.1, allow_negative_numbers = true, value_parser = parse_pitch)]
    pub pitch: f64,
    /// Multiply the framing distance, from 0.001 to 1000 (less than 1 zooms in).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true, value_parser = parse_zoom)]
    pub zoom: f64,
    /// Samples per pixel along each axis, 1 to 4 (2 = 4× anti-aliasing, 1 = off).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=4))]
    pub supersample: u32,
}

/// Image sides in pixels.
const SIDE: std::ops::RangeInclusive<u32> = 8..=8192;
/// Camera rotation about the vertical, degrees.
const YAW: (f64, f64) = (-3600.0, 3600.0);
/// Camera elevation, degrees: at ±90° the view direction is the up vector and the camera
/// has no orientation.
const PITCH: (f64, f64) = (-89.0, 89.0);
/// Factor on the framing distance.
const ZOOM: (f64, f64) = (1e-3, 1e3);

/// Parses `WIDTHxHEIGHT`, each from 8 to 8192 pixels.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once('x')
        .ok_or_else(|| format!("expected WIDTHxHEIGHT such as 800x600, found '{s}'"))?;
    let parse = |v: &str| v.parse::<u32>().ok().filter(|n| SIDE.contains(n));
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!(
            "expected WIDTHxHEIGHT with each from 8 to 8192, found '{s}'"
        )),
    }
}

/// Parses a number within `[lo, hi]` for a command-line option.
pub fn parse_within(s: &str, lo: f64, hi: f64, what: &str) -> Result<f64, String> {
    let x: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("expected {what}, found '{s}'"))?;
    in_range(x, (lo, hi), what, s)
}

/// `x` when it is finite and within `[lo, hi]`; otherwise what `what` expects, with `x`
/// shown as `shown` (the text given on a command line).
fn in_range(x: f64, (lo, hi): (f64, f64), what: &str, shown: &str) -> Result<f64, String> {
    if x.is_finite() && (lo..=hi).contains(&x) {
        Ok(x)
    } else {
        Err(format!(
            "expected {what} from {} to {}, found {shown}",
            hooke_core::Num(lo),
            hooke_core::Num(hi)
        ))
    }
}

fn parse_angle(s: &str) -> Result<f64, String> {
    parse_within(s, YAW.0, YAW.1, "an angle in degrees")
}

fn parse_pitch(s: &str) -> Result<f64, String> {
    parse_within(s, PITCH.0, PITCH.1, "an elevation in degrees")
}

fn parse_zoom(s: &str) -> Result<f64, String> {
    parse_within(s, ZOOM.0, ZOOM.1, "a zoom factor")
}

/// [`in_range`] for a value given in code: `option: expected …`.
fn within(option: &str, x: f64, range: (f64, f64), what: &str) -> Result<f64> {
    in_range(x, range, what, &hooke_core::Num(x).to_string())
        .map_err(|e| anyhow::anyhow!("{option}: {e}"))
}

impl View {
    /// A view from values given in code (the Python package's `render`), checked as the
    /// command line checks its options: size 8 to 8192 each way, style `solid`, `springs`
    /// or `both`, yaw within ±3600°, pitch within ±89°, zoom 0.001 to 1000, supersample 1
    /// to 4.
    ///
    /// ```
    /// use hooke_cli::image_out::View;
    /// assert!(View::checked((320, 240), "solid", (30.0, 22.0), 1.0, 2).is_ok());
    /// assert!(View::checked((320, 240), "solid", (30.0, 95.0), 1.0, 2).is_err());
    /// assert!(View::checked((320, 240), "wire", (30.0, 22.0), 1.0, 2).is_err());
    /// ```
    pub fn checked(
        (width, height): (u32, u32),
        style: &str,
        (yaw, pitch): (f64, f64),
        zoom: f64,
        supersample: u32,
    ) -> Result<Self> {
        if !(SIDE.contains(&width) && SIDE.contains(&height)) {
            anyhow::bail!(
                "size: expected WIDTHxHEIGHT with each from 8 to 8192, found '{width}x{height}'"
            );
        }
        let style = <Style as clap::ValueEnum>::from_str(style, true).map_err(|_| {
            anyhow::anyhow!("style: expected solid, springs or both, found '{style}'")
        })?;
        if !(1..=4).contains(&supersample) {
            anyhow::bail!("supersample: expected 1 to 4, found {supersample}");
        }
        Ok(Self {
            size: (width, height),
            style,
            yaw: within("yaw", yaw, YAW, "an angle in degrees")?,
            pitch: within("pitch", pitch, PITCH, "an elevation in degrees")?,
            zoom: within("zoom", zoom, ZOOM, "a zoom factor")?,
            supersample,
        })
    }

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
            supersample: self.supersample,
            ..RenderOptions::default()
        };
        let pixels = render(&draw(scene, self.style), camera, &options);
        RgbaImage::from_raw(self.size.0, self.size.1, pixels)
            .expect("renderer returns width × height pixels")
    }
}

/// The options `hooke render` takes that decide the picture, for [`picture_from_args`].
#[derive(clap::Parser, Debug)]
#[command(name = "render")]
struct PictureArgs {
    /// Built-in scene name.
    scene: String,
    /// Simulated time of the picture, seconds.
    #[arg(long, allow_negative_numbers = true)]
    at: Option<f64>,
    #[command(flatten)]
    view: View,
}

/// The argument-to-picture path of `hooke render`, in process and without files: `args`
/// as on the command line after `render` (`chain --at 0.5 --zoom 2 --size 64x48`), the
/// scene built, run to `--at` as `render` takes it ([`crate::driver::steps_to`]; at most
/// `max_steps` steps, so that a fuzzer's `--at 1e9` stays quick) and drawn. Any argument
/// is either refused with an error or gives a picture of the asked size; nothing panics. The fuzz target `args` and a property test drive it.
pub fn picture_from_args(args: &[String], max_steps: u64) -> Result<RgbaImage> {
    use clap::Parser;
    let parsed = PictureArgs::try_parse_from(
        std::iter::once("render".to_string()).chain(args.iter().cloned()),
    )?;
    let mut scene = crate::source::build(&parsed.scene, &hooke_scene::Overrides::default())?;
    let steps = crate::driver::steps_to(&scene, parsed.at)?.min(max_steps);
    crate::driver::advance(&mut scene, steps)?;
    let camera = parsed.view.camera(&scene);
    Ok(parsed.view.pixels(&scene, &camera))
}

/// Encodes and writes a PNG atomically.
pub fn write_png(path: &Path, image: &RgbaImage) -> Result<()> {
    let mut bytes = Vec::new();
    image
        .write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    write_atomic(path, &bytes)
}

/// A looping GIF animation written frame by frame; it appears at its path only on
/// [`GifWriter::finish`], and a writer dropped unfinished leaves nothing behind.
pub struct GifWriter {
    path: PathBuf,
    encoder: gif::Encoder<OutputFile>,
    size: (u16, u16),
    /// Frame delay, hundredths of a second (GIF's unit).
    delay: u16,
    frames: u64,
}

impl GifWriter {
    /// Starts a GIF of `size` pixels showing each frame for `frame_ms` milliseconds
    /// (rounded to GIF's 10 ms, at least 20 ms: viewers slow faster frames down).
    pub fn create(path: &Path, size: (u32, u32), frame_ms: u32) -> Result<Self> {
        let cannot = || format!("cannot write {}", path.display());
        let w = u16::try_from(size.0).with_context(cannot)?;
        let h = u16::try_from(size.1).with_context(cannot)?;
        let file = OutputFile::create(path)?;
        let mut encoder = gif::Encoder::new(file, w, h, &[]).with_context(cannot)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .with_context(cannot)?;
        let delay = (frame_ms.div_ceil(10)).clamp(2, u16::MAX as u32) as u16;
        Ok(Self {
            path: path.to_path_buf(),
            encoder,
            size: (w, h),
            delay,
            frames: 0,
        })
    }

    /// Quantises and appends one frame of the GIF's size.
    pub fn frame(&mut self, mut image: RgbaImage) -> Result<()> {
        anyhow::ensure!(
            image.dimensions() == (self.size.0 as u32, self.size.1 as u32),
            "GIF frame of {:?} pixels in a GIF of {:?}",
            image.dimensions(),
            self.size
        );
        // Speed 10 as image's encoder uses: NeuQuant on a sample of the pixels.
        let mut frame = gif::Frame::from_rgba_speed(self.size.0, self.size.1, &mut image, 10);
        frame.delay = self.delay;
        self.encoder
            .write_frame(&frame)
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        self.frames += 1;
        Ok(())
    }

    /// Frames written so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Ends the GIF and puts it in place.
    pub fn finish(self) -> Result<()> {
        let file = self
            .encoder
            .into_inner()
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        file.commit()
    }
}
