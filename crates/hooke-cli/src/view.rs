//! `hooke view`: the scenes live in a window, drawn by our rasterizer, with the course's
//! controls.
//!
//! Each frame the simulation advances by the wall-clock time since the last frame (in whole
//! steps, at most [`MAX_SIM_SHARE`] of a frame's budget, so a slow scene runs slower than
//! real time rather than freezing the window), or by a fixed `--clock` of simulated time,
//! then the scene is drawn and the overlay written on top.

use crate::draw::{DEFAULT_YAW_PITCH, Style, draw_tinted, frame_camera};
use crate::source;
use anyhow::{Context, Result};
use font8x8::UnicodeFonts;
use hooke::image_out::write_png;
use hooke::{driver, interrupt};
use hooke_core::{Air, Attachment, SpringKind, Vec3};
use hooke_render::{Camera, RenderOptions, Renderer};
use hooke_scene::{Overrides, Scene};
use image::RgbaImage;
use minifb::{Key, KeyRepeat, MouseButton, MouseMode, Window, WindowOptions};
use nalgebra::Vector4;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Options of `hooke view`.
#[derive(clap::Args)]
pub struct ViewArgs {
    /// Scenes to cycle through with TAB: built-in names, .toml scenes or .w worlds
    /// (default: the nine built-ins).
    scenes: Vec<String>,
    /// Window size as WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600", value_parser = hooke_cli::args::parse_size)]
    size: (u32, u32),
    /// Samples per pixel along each axis, 1 to 4 (1 = fastest, 2 = 4× anti-aliasing).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4))]
    supersample: u32,
    /// Folder for screenshots (SPACE).
    #[arg(long, default_value = ".")]
    screenshots: PathBuf,
    /// Close after this many frames and print the frame-rate figures (for measurements).
    #[arg(long)]
    frames: Option<u64>,
    /// Advance exactly this many seconds of simulated time per frame, however long a frame
    /// takes (default: keep pace with the wall clock). For recordings, and for tests that
    /// must see the same motion on a loaded machine as on a quiet one.
    #[arg(long, value_name = "SECONDS", value_parser = parse_clock)]
    clock: Option<f64>,
    /// Step every scene with this integrator (default: each scene's own), e.g. `vbd` with
    /// `--dt 0.016666666666666666` for a large cloth at one step per frame.
    #[arg(long)]
    integrator: Option<hooke_core::Integrator>,
    /// Step every scene with this step size in seconds (default: each scene's own).
    #[arg(long, value_parser = crate::parse_seconds)]
    dt: Option<f64>,
}

/// A frame's simulated time: finite, positive, at most a second.
fn parse_clock(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 && x <= 1.0 => Ok(x),
        _ => Err(format!(
            "expected seconds of simulated time per frame, above 0 and at most 1, found '{s}'"
        )),
    }
}

const HELP: [&str; 2] = [
    "TAB scene  R replay  drag rotate  SHIFT+drag/wheel/Z/X zoom  right-drag grab  G shadows  C colour",
    "P pause  V solid/springs  S/H/B struct/shear/bend  W wind  E camera  SPACE shot  ESC quit",
];

/// At most this share of a frame's time is spent simulating (at 30 frames per second).
const MAX_SIM_SHARE: f64 = 0.6;
/// The frame time the simulation budget is computed against.
const FRAME: f64 = 1.0 / 30.0;

/// The particle held with the right mouse button: its depth on screen at the grab.
struct Grab {
    particle: usize,
    ndc_depth: f64,
}

/// Which lattice spring families the springs style draws (springs of no family always are).
#[derive(Clone, Copy, Debug)]
struct Families {
    structural: bool,
    shear: bool,
    bend: bool,
}

impl Families {
    const ALL: Self = Self {
        structural: true,
        shear: true,
        bend: true,
    };
}

struct Viewer {
    scenes: Vec<String>,
    /// The integrator and step every scene is loaded with.
    overrides: Overrides,
    current: usize,
    scene: Scene,
    camera: Camera,
    home: Camera,
    /// The quantity the bodies are coloured by (C cycles none, strain, speed, gap).
    color: hooke::quantity::ColorBy,
    /// Whether the key light casts shadows (G toggles).
    shadows: bool,
    paused: bool,
    style: Style,
    /// The spring families shown in the springs style (s / h / b toggle them).
    families: Families,
    /// The scene's air while W has turned its wind off (the air itself stays: a cloth
    /// still meets drag as it moves).
    windless: Option<Air>,
    /// Wall-clock time owed to the simulation, seconds.
    owed: f64,
    message: Option<String>,
    grab: Option<Grab>,
    last_mouse: Option<(f32, f32)>,
    shots: u32,
}

fn load(arg: &str, overrides: &Overrides) -> Result<(Scene, Camera)> {
    let scene = source::build(arg, overrides)?;
    let camera = frame_camera(&scene, DEFAULT_YAW_PITCH.0, DEFAULT_YAW_PITCH.1);
    // Room for the motion to come: cloth swings, jelly falls, chains sway.
    let camera = Camera {
        distance: camera.distance * 1.3,
        ..camera
    };
    Ok((scene, camera))
}

impl Viewer {
    fn new(scenes: Vec<String>, overrides: Overrides) -> Result<Self> {
        let (scene, camera) = load(&scenes[0], &overrides)?;
        Ok(Self {
            scenes,
            overrides,
            current: 0,
            scene,
            camera,
            home: camera,
            paused: false,
            shadows: true,
            color: hooke::quantity::ColorBy::None,
            style: Style::Solid,
            families: Families::ALL,
            windless: None,
            owed: 0.0,
            message: None,
            grab: None,
            last_mouse: None,
            shots: 0,
        })
    }

    fn switch(&mut self, index: usize) -> Result<()> {
        let (scene, camera) = load(&self.scenes[index], &self.overrides)?;
        self.current = index;
        self.scene = scene;
        self.camera = camera;
        self.home = camera;
        self.owed = 0.0;
        self.message = None;
        self.grab = None;
        self.windless = None;
        Ok(())
    }

    /// Turns the scene's wind (and gusts) off, or back on; scenes without air have none.
    fn toggle_wind(&mut self) {
        let sim = &mut self.scene.simulation;
        if let Some(air) = self.windless.take() {
            sim.set_air(Some(air));
        } else if let Some(air) = sim.model().air.clone() {
            sim.set_air(Some(Air {
                wind: Vec3::zeros(),
                gust: None,
                ..air.clone()
            }));
            self.windless = Some(air);
        }
    }

    /// Restarts the current scene, keeping the camera.
    fn replay(&mut self) -> Result<()> {
        let camera = self.camera;
        self.switch(self.current)?;
        self.camera = camera;
        Ok(())
    }

    fn zoom(&mut self, factor: f64) {
        self.camera.distance = (self.camera.distance * factor).clamp(0.05, 500.0);
    }

    fn rotate(&mut self, dx: f32, dy: f32) {
        self.camera.yaw -= dx as f64 * 0.4;
        self.camera.pitch = (self.camera.pitch + dy as f64 * 0.4).clamp(-89.0, 89.0);
    }

    /// Advances the simulation by `wall` seconds, in whole steps, within [`MAX_SIM_SHARE`]
    /// of a frame when keeping pace with the wall clock, or all of them with a fixed
    /// `--clock` (`fixed`).
    fn simulate(&mut self, wall: f64, fixed: bool) {
        if self.paused || self.message.is_some() {
            return;
        }
        let budget = if fixed {
            Duration::MAX
        } else {
            Duration::from_secs_f64(MAX_SIM_SHARE * FRAME)
        };
        match driver::catch_up(&mut self.scene, self.owed + wall, budget) {
            Ok(owed) => self.owed = owed,
            // The window loop sees the interrupt itself and closes.
            Err(e) if interrupt::is_interrupt(&e) => self.owed = 0.0,
            Err(e) => self.message = Some(format!("{e}")),
        }
    }

    fn show(&self, kind: SpringKind) -> bool {
        let f = &self.families;
        match kind {
            SpringKind::Structural => f.structural,
            SpringKind::Shear => f.shear,
            SpringKind::Bend => f.bend,
            SpringKind::Other => true,
        }
    }

    fn options(&self, size: (u32, u32), supersample: u32) -> RenderOptions {
        RenderOptions {
            width: size.0,
            height: size.1,
            supersample,
            shadows: self.shadows,
            ..RenderOptions::default()
        }
    }

    /// Window pixel → normalised device coordinates.
    fn ndc(&self, (mx, my): (f32, f32), size: (u32, u32)) -> (f64, f64) {
        (
            mx as f64 / size.0 as f64 * 2.0 - 1.0,
            1.0 - my as f64 / size.1 as f64 * 2.0,
        )
    }

    /// Starts a grab at the particle nearest the cursor, within 30 pixels.
    fn pick(&mut self, mouse: (f32, f32), size: (u32, u32)) {
        let m = self.camera.view_projection(size.0 as f64 / size.1 as f64);
        let p = self.scene.simulation.particles();
        let mut best: Option<(f64, usize, f64)> = None;
        for (i, x) in p.x.iter().enumerate() {
            if p.is_pinned(i) {
                continue;
            }
            let c = m * Vector4::new(x.x, x.y, x.z, 1.0);
            if c.w <= 0.0 {
                continue;
            }
            let (px, py) = (
                (c.x / c.w + 1.0) * 0.5 * size.0 as f64,
                (1.0 - c.y / c.w) * 0.5 * size.1 as f64,
            );
            let d = (px - mouse.0 as f64).hypot(py - mouse.1 as f64);
            if d < 30.0 && best.is_none_or(|(bd, _, _)| d < bd) {
                best = Some((d, i, c.z / c.w));
            }
        }
        self.grab = best.map(|(_, particle, ndc_depth)| Grab {
            particle,
            ndc_depth,
        });
    }

    /// Pulls the grabbed particle towards the cursor with a spring stiff enough to follow
    /// and soft enough to stay stable at the scene's step (`ω dt = 0.5`).
    fn pull(&mut self, mouse: (f32, f32), size: (u32, u32)) {
        let Some(grab) = &self.grab else {
            return;
        };
        let m = self.camera.view_projection(size.0 as f64 / size.1 as f64);
        let Some(inverse) = m.try_inverse() else {
            return;
        };
        let (nx, ny) = self.ndc(mouse, size);
        let w = inverse * Vector4::new(nx, ny, grab.ndc_depth, 1.0);
        let target = Vec3::new(w.x, w.y, w.z) / w.w;
        let sim = &self.scene.simulation;
        let mass = sim.particles().mass[grab.particle];
        let omega = 0.5 / sim.dt();
        let ks = mass * omega * omega;
        let kd = mass * omega;
        let particle = grab.particle;
        self.scene.simulation.set_attachments(vec![Attachment {
            particle,
            target,
            ks,
            kd,
        }]);
    }

    fn release(&mut self) {
        if self.grab.take().is_some() {
            self.scene.simulation.set_attachments(Vec::new());
        }
    }

    /// Saves the window's picture, overlay included, as `hooke-<scene>-<n>.png`.
    fn screenshot(&mut self, buffer: &[u32], size: (u32, u32), dir: &std::path::Path) {
        self.shots += 1;
        let name = std::path::Path::new(&self.scenes[self.current])
            .file_stem()
            .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
        let path = dir.join(format!("hooke-{name}-{:03}.png", self.shots));
        let pixels = buffer
            .iter()
            .flat_map(|p| [(p >> 16) as u8, (p >> 8) as u8, *p as u8, 255])
            .collect();
        let result = RgbaImage::from_raw(size.0, size.1, pixels)
            .context("frame size")
            .and_then(|image| Ok(write_png(&path, &image)?));
        match result {
            Ok(()) => eprintln!("screenshot: {}", path.display()),
            Err(e) => eprintln!("screenshot failed: {e:#}"),
        }
    }
}

/// Writes `text` at `(x, y)` with the 8×8 public-domain font, white on a dark shadow.
fn text(buffer: &mut [u32], width: usize, height: usize, x: usize, y: usize, text: &str) {
    for (k, c) in text.chars().enumerate() {
        let Some(glyph) = font8x8::BASIC_FONTS.get(c) else {
            continue;
        };
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits >> col & 1 == 0 {
                    continue;
                }
                let (px, py) = (x + k * 8 + col, y + row);
                for (dx, dy, colour) in [(1, 1, 0x0020_2020u32), (0, 0, 0x00ff_ffff)] {
                    let (qx, qy) = (px + dx, py + dy);
                    if qx < width && qy < height {
                        buffer[qy * width + qx] = colour;
                    }
                }
            }
        }
    }
}

/// Runs the viewer until the window closes (or `--frames` are shown).
pub fn run(args: &ViewArgs) -> Result<ExitCode> {
    let scenes = if args.scenes.is_empty() {
        hooke_scene::builtin::BUILTINS
            .iter()
            .map(|(name, _)| name.to_string())
            .collect()
    } else {
        args.scenes.clone()
    };
    // Load every scene first, so a bad argument fails before a window opens.
    for s in &scenes {
        source::read(s)?;
    }
    let overrides = Overrides {
        integrator: args.integrator,
        dt: args.dt,
        ..Overrides::default()
    };
    std::fs::create_dir_all(&args.screenshots).with_context(|| {
        format!(
            "cannot create screenshot folder {}",
            args.screenshots.display()
        )
    })?;
    let size = args.size;
    let (w, h) = (size.0 as usize, size.1 as usize);
    let mut window = Window::new("hooke", w, h, WindowOptions::default()).map_err(|e| {
        anyhow::anyhow!(
            "cannot open a window: {e} (hooke view needs an X11 display: is DISPLAY set? \
             Without one, run `Xvfb :99 & DISPLAY=:99 hooke view`, or use `hooke render`)"
        )
    })?;
    window.set_target_fps(0);
    let mut viewer = Viewer::new(scenes, overrides)?;
    let mut renderer = Renderer::default();
    let pool = hooke::threads::pool(None, "--threads")?;
    let mut buffer = vec![0u32; w * h];
    let options = viewer.options(size, args.supersample);

    let started = Instant::now();
    let mut last = Instant::now();
    let mut frames = 0u64;
    let (mut sim_time, mut render_time) = (Duration::ZERO, Duration::ZERO);
    let mut fps = 0.0;
    let mut window_start = (Instant::now(), 0u64);
    while window.is_open() && !window.is_key_down(Key::Escape) && !interrupt::requested() {
        let now = Instant::now();
        let wall = args.clock.unwrap_or((now - last).as_secs_f64().min(0.25));
        last = now;

        for key in window.get_keys_pressed(KeyRepeat::No) {
            match key {
                Key::Tab => viewer.switch((viewer.current + 1) % viewer.scenes.len())?,
                Key::R => viewer.replay()?,
                Key::P => viewer.paused = !viewer.paused,
                Key::G => viewer.shadows = !viewer.shadows,
                Key::C => {
                    use hooke::quantity::ColorBy;
                    viewer.color = match viewer.color {
                        ColorBy::None => ColorBy::Strain,
                        ColorBy::Strain => ColorBy::Speed,
                        ColorBy::Speed => ColorBy::Gap,
                        ColorBy::Gap => ColorBy::None,
                    };
                }
                Key::V => {
                    viewer.style = match viewer.style {
                        Style::Solid => Style::Springs,
                        _ => Style::Solid,
                    }
                }
                Key::S => viewer.families.structural ^= true,
                Key::H => viewer.families.shear ^= true,
                Key::B => viewer.families.bend ^= true,
                Key::W => viewer.toggle_wind(),
                Key::E => viewer.camera = viewer.home,
                Key::Z => viewer.zoom(0.9),
                Key::X => viewer.zoom(1.0 / 0.9),
                _ => {}
            }
        }
        let shift = window.is_key_down(Key::LeftShift) || window.is_key_down(Key::RightShift);
        let mouse = window.get_mouse_pos(MouseMode::Clamp);
        if let (Some(m), Some(prev)) = (mouse, viewer.last_mouse)
            && window.get_mouse_down(MouseButton::Left)
        {
            let (dx, dy) = (m.0 - prev.0, m.1 - prev.1);
            if shift {
                viewer.zoom((dy as f64 * 0.01).exp());
            } else {
                viewer.rotate(dx, dy);
            }
        }
        if let Some((_, wheel)) = window.get_scroll_wheel() {
            viewer.zoom((-wheel as f64 * 0.1).exp());
        }
        match (mouse, window.get_mouse_down(MouseButton::Right)) {
            (Some(m), true) => {
                if viewer.grab.is_none() {
                    viewer.pick(m, size);
                }
                viewer.pull(m, size);
            }
            _ => viewer.release(),
        }
        viewer.last_mouse = mouse;

        // The window stays on this thread; the work of a frame runs on a pool worker, where
        // the solver's and rasterizer's parallel loops are cheap joins.
        let t0 = Instant::now();
        pool.install(|| viewer.simulate(wall, args.clock.is_some()));
        let t1 = Instant::now();
        let pixels = pool.install(|| {
            // A quantity's colours each frame on its own range (rounded up), with its legend.
            let by = viewer.color;
            let shown = by.values(&viewer.scene).map(|values| {
                let range = by.default_range(&viewer.scene, &values);
                (by.colors(&values, range), range)
            });
            let tint = shown.as_ref().map(|(colors, _)| colors.as_slice());
            let list = draw_tinted(&viewer.scene, viewer.style, |k| viewer.show(k), tint);
            let options = RenderOptions {
                ambient: if shown.is_some() {
                    0.7
                } else {
                    options.ambient
                },
                ..options
            };
            let mut pixels = renderer.render(&list, &viewer.camera, &options);
            if let Some((_, range)) = shown {
                by.legend(&viewer.scene, range)
                    .draw(&mut pixels, options.width, options.height);
            }
            pixels
        });
        for (o, p) in buffer.iter_mut().zip(pixels.chunks_exact(4)) {
            *o = (p[0] as u32) << 16 | (p[1] as u32) << 8 | p[2] as u32;
        }
        sim_time += t1 - t0;
        render_time += t1.elapsed();

        frames += 1;
        let since = window_start.0.elapsed().as_secs_f64();
        if since >= 0.5 {
            fps = (frames - window_start.1) as f64 / since;
            window_start = (Instant::now(), frames);
        }
        let sim = &viewer.scene.simulation;
        let status = format!(
            "{} ({}/{})  t = {:.2} s  {:.0} fps  {}{}{}",
            viewer.scene.spec.name,
            viewer.current + 1,
            viewer.scenes.len(),
            sim.time(),
            fps,
            sim.integrator(),
            if viewer.windless.is_some() {
                "  WIND OFF"
            } else {
                ""
            },
            if viewer.paused { "  PAUSED" } else { "" }
        );
        text(&mut buffer, w, h, 8, 8, &status);
        if let Some(m) = &viewer.message {
            text(&mut buffer, w, h, 8, 24, m);
        }
        text(&mut buffer, w, h, 8, h.saturating_sub(28), HELP[0]);
        text(&mut buffer, w, h, 8, h.saturating_sub(16), HELP[1]);
        if window.is_key_pressed(Key::Space, KeyRepeat::No) {
            viewer.screenshot(&buffer, size, &args.screenshots);
        }
        window
            .update_with_buffer(&buffer, w, h)
            .context("cannot draw into the window")?;
        if args.frames.is_some_and(|n| frames >= n) {
            break;
        }
    }
    let elapsed = started.elapsed().as_secs_f64();
    eprintln!(
        "viewer: {frames} frames in {elapsed:.2} s ({:.1} fps); per frame {:.1} ms simulating, {:.1} ms drawing",
        frames as f64 / elapsed,
        sim_time.as_secs_f64() * 1e3 / frames.max(1) as f64,
        render_time.as_secs_f64() * 1e3 / frames.max(1) as f64,
    );
    if interrupt::requested() {
        eprintln!("interrupted: viewer closed");
        return Ok(ExitCode::from(interrupt::EXIT_INTERRUPTED));
    }
    Ok(ExitCode::SUCCESS)
}
