//! Command-line options shared by the commands that draw, checked as the library's
//! [`View::checked`] checks values given in code.

use hooke::draw::{DEFAULT_YAW_PITCH, Style};
use hooke::image_out::{PITCH, SIDE, View, YAW, ZOOM, in_range};
use hooke::quantity::ColorBy;
use image::RgbaImage;

/// Camera placement options shared by the commands that draw.
#[derive(clap::Args, Clone, Debug)]
pub struct ViewArgs {
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
    /// Place the camera: AZIMUTH,ELEVATION,DISTANCE (degrees about the vertical, degrees
    /// above the horizontal, metres from the framed centre), or a named view: front, back,
    /// left, right, top or three-quarter (the default framing). Replaces --yaw and --pitch.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_camera)]
    pub camera: Option<Placement>,
    /// Colour the bodies by a quantity, with a legend: strain (each structural spring's
    /// (length − rest)/rest averaged to its particles, %), speed (m/s) or gap (to the
    /// nearest collider, m, the contact thickness marked).
    #[arg(long, value_enum, default_value_t = ColorBy::None)]
    pub color: ColorBy,
    /// The colour map's range as LO,HI in the quantity's unit (default: the frame's own,
    /// rounded up; an animation takes its range from a first pass over the run).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_range)]
    pub range: Option<(f64, f64)>,
    /// Draw without shadows.
    #[arg(long)]
    pub no_shadows: bool,
}

/// Where `--camera` puts the camera: yaw, pitch (degrees) and the distance (metres; `None`:
/// the framing's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    yaw: f64,
    pitch: f64,
    distance: Option<f64>,
}

/// Parses `--camera`: `AZIMUTH,ELEVATION,DISTANCE` or a named view.
fn parse_camera(s: &str) -> Result<Placement, String> {
    let named = |yaw: f64, pitch: f64| {
        Ok(Placement {
            yaw,
            pitch,
            distance: None,
        })
    };
    match s.trim().to_ascii_lowercase().as_str() {
        "front" => return named(0.0, 10.0),
        "back" => return named(180.0, 10.0),
        "right" => return named(90.0, 10.0),
        "left" => return named(-90.0, 10.0),
        "top" => return named(0.0, 89.0),
        "three-quarter" => return named(DEFAULT_YAW_PITCH.0, DEFAULT_YAW_PITCH.1),
        _ => {}
    }
    let parts: Vec<&str> = s.split(',').collect();
    let [az, el, d] = parts[..] else {
        return Err(format!(
            "expected AZIMUTH,ELEVATION,DISTANCE (degrees, degrees, metres) such as \
             30,20,4 or a view (front, back, left, right, top, three-quarter), found '{s}'"
        ));
    };
    Ok(Placement {
        yaw: parse_within(az, YAW.0, YAW.1, "an azimuth in degrees")?,
        pitch: parse_within(el, PITCH.0, PITCH.1, "an elevation in degrees")?,
        distance: Some(parse_within(d, 1e-3, 1e6, "a distance in metres")?),
    })
}

/// Parses `--range LO,HI`: two finite numbers, LO below HI.
fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let (lo, hi) = s
        .split_once(',')
        .ok_or_else(|| format!("expected LO,HI such as -5,5, found '{s}'"))?;
    let number = |v: &str| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite() && x.abs() <= 1e12)
            .ok_or_else(|| format!("expected LO,HI with numbers within ±1e12, found '{s}'"))
    };
    let (lo, hi) = (number(lo)?, number(hi)?);
    if lo >= hi {
        return Err(format!("expected LO below HI, found '{s}'"));
    }
    Ok((lo, hi))
}

impl ViewArgs {
    /// The library's view these options describe.
    pub fn view(&self) -> View {
        let placed = self.camera;
        View {
            size: self.size,
            style: self.style,
            yaw: placed.map_or(self.yaw, |p| p.yaw),
            pitch: placed.map_or(self.pitch, |p| p.pitch),
            zoom: self.zoom,
            supersample: self.supersample,
            distance: placed.and_then(|p| p.distance),
            shadows: !self.no_shadows,
            color: self.color,
            range: self.range,
        }
    }
}

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

fn parse_angle(s: &str) -> Result<f64, String> {
    parse_within(s, YAW.0, YAW.1, "an angle in degrees")
}

fn parse_pitch(s: &str) -> Result<f64, String> {
    parse_within(s, PITCH.0, PITCH.1, "an elevation in degrees")
}

fn parse_zoom(s: &str) -> Result<f64, String> {
    parse_within(s, ZOOM.0, ZOOM.1, "a zoom factor")
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
    view: ViewArgs,
}

/// The argument-to-picture path of `hooke render`, in process and without files: `args`
/// as on the command line after `render` (`chain --at 0.5 --zoom 2 --size 64x48`), the
/// scene built, run to `--at` as `render` takes it ([`hooke::driver::steps_to`]; at most
/// `max_steps` steps, so that a fuzzer's `--at 1e9` stays quick) and drawn. Any argument
/// is either refused with an error or gives a picture of the asked size; nothing panics.
/// The fuzz target `args` and a property test drive it.
pub fn picture_from_args(args: &[String], max_steps: u64) -> anyhow::Result<RgbaImage> {
    use clap::Parser;
    let parsed = PictureArgs::try_parse_from(
        std::iter::once("render".to_string()).chain(args.iter().cloned()),
    )?;
    let mut scene = hooke::source::build(&parsed.scene, &hooke::scene::Overrides::default())?;
    let steps = hooke::driver::steps_to(&scene, parsed.at)?.min(max_steps);
    hooke::driver::advance(&mut scene, steps)?;
    let view = parsed.view.view();
    let camera = view.camera(&scene);
    Ok(view.pixels(&scene, &camera))
}
