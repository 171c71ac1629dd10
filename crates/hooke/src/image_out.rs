//! Rendering scenes to PNG stills and GIF animations, written atomically; a GIF is encoded
//! frame by frame as a run produces them, so its memory does not grow with its length.

use crate::draw::{Style, draw_tinted, frame_camera};
use crate::error::{Context, Result};
use crate::output::{OutputFile, write_atomic, write_named};
use crate::quantity::ColorBy;
use hooke_render::{Camera, RenderOptions, render};
use hooke_scene::Scene;
use image::{ImageFormat, RgbaImage};
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// Where the camera looks from and what it draws: what a still needs besides the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    /// Image size in pixels, width and height, each from 8 to 8192.
    pub size: (u32, u32),
    /// What to draw.
    pub style: Style,
    /// Camera rotation about the vertical, degrees.
    pub yaw: f64,
    /// Camera elevation, degrees, from -89 to 89.
    pub pitch: f64,
    /// Factor on the framing distance, from 0.001 to 1000 (less than 1 zooms in).
    pub zoom: f64,
    /// Samples per pixel along each axis, 1 to 4 (2 = 4× anti-aliasing, 1 = off).
    pub supersample: u32,
    /// The camera's distance from the framed centre, metres (`None`: the framing's, times
    /// `zoom`).
    pub distance: Option<f64>,
    /// Whether the key light casts shadows.
    pub shadows: bool,
    /// The quantity the bodies are coloured by, with a legend.
    pub color: ColorBy,
    /// The colour map's range, in the quantity's unit (`None`: each frame's own, rounded
    /// up; an animation fixes it for all its frames).
    pub range: Option<(f64, f64)>,
}

impl Default for View {
    /// The command line's defaults: 800×600, solid, yaw 30°, pitch 22°, 4× anti-aliasing.
    fn default() -> Self {
        Self {
            size: (800, 600),
            style: crate::draw::Style::Solid,
            yaw: crate::draw::DEFAULT_YAW_PITCH.0,
            pitch: crate::draw::DEFAULT_YAW_PITCH.1,
            zoom: 1.0,
            supersample: 2,
            distance: None,
            shadows: true,
            color: ColorBy::None,
            range: None,
        }
    }
}

/// Image sides in pixels.
pub const SIDE: std::ops::RangeInclusive<u32> = 8..=8192;
/// Camera rotation about the vertical, degrees.
pub const YAW: (f64, f64) = (-3600.0, 3600.0);
/// Camera elevation, degrees: at ±90° the view direction is the up vector and the camera
/// has no orientation.
pub const PITCH: (f64, f64) = (-89.0, 89.0);
/// Factor on the framing distance.
pub const ZOOM: (f64, f64) = (1e-3, 1e3);

/// `x` when it is finite and within `[lo, hi]`; otherwise what `what` expects, with `x`
/// shown as `shown` (the text given on a command line).
pub fn in_range(x: f64, (lo, hi): (f64, f64), what: &str, shown: &str) -> Result<f64, String> {
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

/// [`in_range`] for a value given in code: `option: expected …`.
fn within(option: &str, x: f64, range: (f64, f64), what: &str) -> Result<f64> {
    in_range(x, range, what, &hooke_core::Num(x).to_string())
        .map_err(|e| crate::Error::input(format!("{option}: {e}")))
}

impl View {
    /// A view from values given in code (the Python package's `render`), checked as the
    /// command line checks its options: size 8 to 8192 each way, style `solid`, `springs`
    /// or `both`, yaw within ±3600°, pitch within ±89°, zoom 0.001 to 1000, supersample 1
    /// to 4.
    ///
    /// ```
    /// use hooke::image_out::View;
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
            crate::error::bail_input!(
                "size: expected WIDTHxHEIGHT with each from 8 to 8192, found '{width}x{height}'"
            );
        }
        let style = Style::from_name(style).ok_or_else(|| {
            crate::Error::input(format!(
                "style: expected solid, springs or both, found '{style}'"
            ))
        })?;
        if !(1..=4).contains(&supersample) {
            crate::error::bail_input!("supersample: expected 1 to 4, found {supersample}");
        }
        Ok(Self {
            size: (width, height),
            style,
            yaw: within("yaw", yaw, YAW, "an angle in degrees")?,
            pitch: within("pitch", pitch, PITCH, "an elevation in degrees")?,
            zoom: within("zoom", zoom, ZOOM, "a zoom factor")?,
            supersample,
            ..Self::default()
        })
    }

    /// The camera for the scene's current state.
    pub fn camera(&self, scene: &Scene) -> Camera {
        let mut camera = frame_camera(scene, self.yaw, self.pitch);
        if let Some(d) = self.distance {
            camera.distance = d;
        }
        camera.distance *= self.zoom;
        camera
    }

    /// The quantity's values on the scene now and the range they are shown with (the
    /// view's, or their own rounded up); `None` without a quantity.
    pub fn quantity(&self, scene: &Scene) -> Option<(Vec<f64>, (f64, f64))> {
        let values = self.color.values(scene)?;
        let range = self
            .range
            .unwrap_or_else(|| self.color.default_range(scene, &values));
        Some((values, range))
    }

    /// Renders the scene's current state to RGBA pixels, with the quantity's legend.
    pub fn pixels(&self, scene: &Scene, camera: &Camera) -> RgbaImage {
        let options = RenderOptions {
            width: self.size.0,
            height: self.size.1,
            supersample: self.supersample,
            shadows: self.shadows,
            // A quantity's colours read on the side away from the light too.
            ambient: if self.color == ColorBy::None {
                0.35
            } else {
                0.7
            },
            ..RenderOptions::default()
        };
        let shown = self
            .quantity(scene)
            .map(|(values, range)| (self.color.colors(&values, range), range));
        let tint = shown.as_ref().map(|(colors, _)| colors.as_slice());
        let list = draw_tinted(scene, self.style, |_| true, tint);
        let mut pixels = render(&list, camera, &options);
        if let Some((_, range)) = shown {
            self.color
                .legend(scene, range)
                .draw(&mut pixels, self.size.0, self.size.1);
        }
        RgbaImage::from_raw(self.size.0, self.size.1, pixels)
            .expect("renderer returns width × height pixels")
    }
}

/// Encodes and writes a PNG atomically at a path the user gave.
pub fn write_png(path: &Path, image: &RgbaImage) -> Result<()> {
    write_atomic(path, &png_bytes(path, image)?)
}

/// Encodes and writes a PNG atomically at `path`, a name hooke chose inside a folder it
/// writes (given with option `flag`; see [`crate::output::named`]).
pub fn write_png_named(path: &Path, flag: &str, image: &RgbaImage) -> Result<()> {
    write_named(path, flag, &png_bytes(path, image)?)
}

/// `image` encoded as a PNG, for `path`.
pub(crate) fn png_bytes(path: &Path, image: &RgbaImage) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    image
        .write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    Ok(bytes)
}

/// A looping GIF animation written frame by frame; it appears at its path only on
/// [`GifWriter::finish`], and a writer dropped unfinished leaves nothing behind.
///
/// GIF counts delays in hundredths of a second, and viewers show a frame of less than two
/// for a tenth of a second. So the animation plays in real time either way: frames at
/// least two hundredths apart are each shown from their own time rounded to the hundredth
/// (1/30 s frames for 3, 4 and 3), and closer ones are shown at 50 a second, each slot of
/// two hundredths taking the frame whose time is nearest it (60 Hz frames: five of every
/// six).
pub struct GifWriter {
    path: PathBuf,
    encoder: gif::Encoder<OutputFile>,
    size: (u16, u16),
    /// Simulated time between frames, hundredths of a second.
    period: f64,
    /// The next slot of [`LEAST_DELAY`] to fill, when frames come faster than slots.
    slot: u64,
    frames: u64,
}

/// The least delay viewers honour, hundredths of a second.
const LEAST_DELAY: u64 = 2;

impl GifWriter {
    /// Starts a GIF of `size` pixels whose frames are `frame_ms` milliseconds of
    /// simulated time apart.
    pub fn create(path: &Path, size: (u32, u32), frame_ms: f64) -> Result<Self> {
        Self::start(OutputFile::create(path)?, path, size, frame_ms)
    }

    /// As [`GifWriter::create`], at `path`, a name hooke chose inside a folder it writes
    /// (given with option `flag`; see [`crate::output::named`]).
    pub fn create_named(path: &Path, flag: &str, size: (u32, u32), frame_ms: f64) -> Result<Self> {
        Self::start(OutputFile::create_named(path, flag)?, path, size, frame_ms)
    }

    fn start(file: OutputFile, path: &Path, size: (u32, u32), frame_ms: f64) -> Result<Self> {
        let cannot = || format!("cannot write {}", path.display());
        let w = u16::try_from(size.0).with_context(cannot)?;
        let h = u16::try_from(size.1).with_context(cannot)?;
        let mut encoder = gif::Encoder::new(file, w, h, &[]).with_context(cannot)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .with_context(cannot)?;
        let period = if frame_ms.is_finite() && frame_ms > 0.0 {
            (frame_ms / 10.0).min(u16::MAX as f64)
        } else {
            LEAST_DELAY as f64
        };
        Ok(Self {
            path: path.to_path_buf(),
            encoder,
            size: (w, h),
            period,
            slot: 0,
            frames: 0,
        })
    }

    /// How long frame `k` is shown, hundredths of a second, or `None` when it is left out.
    fn delay(&mut self, k: u64) -> Option<u16> {
        let p = self.period;
        if p >= LEAST_DELAY as f64 {
            let at = |k: u64| (k as f64 * p).round() as u64;
            return Some((at(k + 1) - at(k)).clamp(LEAST_DELAY, u16::MAX as u64) as u16);
        }
        // The frame nearest slot `j`'s time `2 j`.
        let nearest = (self.slot as f64 * LEAST_DELAY as f64 / p).round() as u64;
        (k == nearest).then(|| {
            self.slot += 1;
            LEAST_DELAY as u16
        })
    }

    /// Quantises and appends one frame of the GIF's size (or leaves it out: see the type).
    pub fn frame(&mut self, mut image: RgbaImage) -> Result<()> {
        if image.dimensions() != (self.size.0 as u32, self.size.1 as u32) {
            crate::error::bail_output!(
                "GIF frame of {:?} pixels in a GIF of {:?}",
                image.dimensions(),
                self.size
            );
        }
        let k = self.frames;
        self.frames += 1;
        let Some(delay) = self.delay(k) else {
            return Ok(());
        };
        // Speed 10 as image's encoder uses: NeuQuant on a sample of the pixels.
        let mut frame = gif::Frame::from_rgba_speed(self.size.0, self.size.1, &mut image, 10);
        frame.delay = delay;
        self.encoder
            .write_frame(&frame)
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        Ok(())
    }

    /// Where the GIF goes.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Frames taken so far (those left out between two slots included).
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The delays a GIF of frames `frame_ms` apart gives its first `n` frames (zero: left
    /// out).
    fn delays(frame_ms: f64, n: u64) -> Vec<u16> {
        let path =
            std::env::temp_dir().join(format!("hooke-gif-{}-{frame_ms}.gif", std::process::id()));
        let mut gif = GifWriter::create(&path, (4, 4), frame_ms).unwrap();
        (0..n).map(|k| gif.delay(k).unwrap_or(0)).collect()
    }

    #[test]
    fn an_animation_plays_in_real_time_and_no_frame_is_under_two_hundredths() {
        for (ms, frames) in [
            (1000.0 / 60.0, 60),
            (1000.0 / 30.0, 30),
            (40.0, 25),
            (100.0, 10),
            (1.0, 1000),
        ] {
            let d = delays(ms, frames);
            let shown: u64 = d.iter().map(|&x| u64::from(x)).sum();
            // One second of frames plays for one second, to a slot.
            assert!(
                (shown as i64 - 100).abs() <= 2,
                "{ms} ms: {shown} cs: {d:?}"
            );
            assert!(d.iter().all(|&x| x == 0 || x >= 2), "{ms} ms: {d:?}");
        }
        // 60 Hz: five frames of every six, each two hundredths; 30 Hz: 3, 4, 3.
        assert_eq!(delays(1000.0 / 60.0, 6), [2, 2, 2, 0, 2, 2]);
        assert_eq!(delays(1000.0 / 30.0, 3), [3, 4, 3]);
    }
}
