//! Cusick's drape test (BS 5058, ISO 9073-9) on any fabric: a disc specimen laid centred on
//! a round pedestal hangs in folds; the drape coefficient is the share of the overhanging
//! ring that its shadow from above covers,
//! `DC = (A_shadow − A_pedestal) / (A_specimen − A_pedestal)`, and the folds are counted as
//! nodes. `hooke drape` runs it; docs/materials.md, "Drape test", states the method.

mod fit;
pub mod measure;

pub use fit::{FIT_RANGE, Fit, fit_bending};

use crate::error::{Context, Result};
use hooke_scene::Scene;
use hooke_scene::material::Material;
use measure::{Shadow, nodes};
use std::f64::consts::PI;

/// The meter and how a run of it ends (docs/materials.md, "Drape test", gives the reasons
/// for each default).
#[derive(Clone, Debug, PartialEq)]
pub struct Meter {
    /// The specimen's diameter, metres: 0.24, 0.30 (the standard's) or 0.36.
    pub specimen: f64,
    /// The pedestal's diameter, metres (0.18).
    pub pedestal: f64,
    /// The specimen's own mesh: an OBJ disc `specimen` across, centred on the origin in the
    /// x–z plane. `None`: the built-in disc of irregular triangles on rings
    /// [`hooke_scene::example_meshes::DRAPE_RING_SPACING`] apart.
    pub mesh: Option<std::path::PathBuf>,
    /// Coulomb friction of the cloth on the pedestal (and of its folds on each other).
    pub friction: f64,
    /// The cloth's contact thickness, metres.
    pub thickness: f64,
    /// The integrator.
    pub integrator: hooke_core::Integrator,
    /// The step, seconds; 0 for four fifths of the estimated stable step of an explicit
    /// integrator.
    pub dt: f64,
    /// The large step's stopping tolerance, m/s.
    pub tolerance: f64,
    /// The large step's iterations at most.
    pub iterations: usize,
    /// The meter's still air: drag per kilogram, 1/s, which brings the specimen to rest
    /// without moving where it rests.
    pub drag: f64,
    /// Settled: the kinetic energy per unit mass below this, J/kg, ...
    pub settle_energy: f64,
    /// ... and the drape coefficient within this band, ...
    pub settle_band: f64,
    /// ... for this long, seconds.
    pub settle_for: f64,
    /// The longest run, seconds: a specimen not settled by then is measured as it is, and
    /// said so.
    pub longest: f64,
    /// Raster cell of the shadow, metres.
    pub cell: f64,
    /// A node rises this far above the valleys beside it, metres.
    pub prominence: f64,
}

impl Default for Meter {
    fn default() -> Self {
        Self {
            specimen: 0.30,
            pedestal: 0.18,
            mesh: None,
            friction: 0.5,
            thickness: 0.001,
            integrator: hooke_core::Integrator::Symplectic,
            dt: 0.0,
            tolerance: 1e-3,
            iterations: 300,
            drag: 5.0,
            settle_energy: 1e-4,
            settle_band: 0.02,
            settle_for: 1.0,
            longest: 15.0,
            cell: 0.0005,
            prominence: 0.004,
        }
    }
}

/// The pedestal's top, metres above the ground.
const TOP: f64 = 0.5;

/// How often the coefficient is read while a repeat settles, seconds.
const READ_EVERY: f64 = 0.25;

impl Meter {
    /// The specimen sizes the standard names, metres.
    pub const SIZES: [f64; 3] = [0.24, 0.30, 0.36];

    /// The specimen's mesh path as a scene names it.
    fn mesh_path(&self) -> Result<String> {
        if let Some(path) = &self.mesh {
            // A mesh shipped with Hooke, by the name the docs give it.
            if let Some(name) = path.to_str().filter(|p| p.starts_with("builtin:")) {
                return Ok(name.to_string());
            }
            let full = std::path::absolute(path)
                .map_err(|e| crate::Error::input(format!("{}: {e}", path.display())))?;
            let text = full.display().to_string();
            // The scene names it in a TOML literal string, which has no escapes.
            if text.contains("'''") || text.contains(['\n', '\r']) {
                return Err(crate::Error::input(format!(
                    "{text}: a specimen's path may not hold a line break or three quotes"
                )));
            }
            return Ok(text);
        }
        match (self.specimen * 100.0).round() as i64 {
            24 => Ok("builtin:drape-24.obj".into()),
            30 => Ok("builtin:drape-30.obj".into()),
            36 => Ok("builtin:drape-36.obj".into()),
            _ => Err(crate::Error::input(format!(
                "a drape specimen is 24, 30 or 36 cm across (BS 5058), not {} cm",
                hooke_core::Num(self.specimen * 100.0)
            ))),
        }
    }

    /// The scene of one repeat of the test for `material`: the specimen tilted and turned
    /// as `seed` says (up to 2° about two horizontal axes, any turn about the vertical), 1 cm
    /// above the pedestal.
    pub fn scene(&self, material: &Material, seed: u64) -> Result<Scene> {
        self.check_specimen()?;
        let scene = self.scene_at(material, seed, self.dt)?;
        if self.dt > 0.0 {
            return Ok(scene);
        }
        // An explicit step of its own: a fifth under the stable step estimated on the flat
        // specimen (the folds' contacts stiffen it; `hooke check` gives the same estimate).
        let stable = scene
            .simulation
            .stability()
            .max_dt(self.integrator)
            .min(1.0 / 60.0);
        self.scene_at(material, seed, 0.8 * stable)
    }

    /// [`Meter::scene`] at the step `dt` (0: any, to be estimated).
    fn scene_at(&self, material: &Material, seed: u64, dt: f64) -> Result<Scene> {
        let dt = if dt > 0.0 { dt } else { 1e-5 };
        let mut state = seed
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(0x2545_F491);
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (tilt_x, turn, tilt_z) = (4.0 * next() - 2.0, 360.0 * next(), 4.0 * next() - 2.0);
        let m = material;
        let mesh = self.mesh_path()?;
        let text = format!(
            r#"
name = "drape"
description = "Cusick's drape test: a {d} cm disc on an {p} cm pedestal"
[simulation]
integrator = "{integrator}"
dt = {dt:e}
duration = {longest:e}
every = 1
mass_drag = {drag:e}
tolerance = {tolerance:e}
iterations = {iterations}
[simulation.air]
density = 1.225
[[body]]
name = "specimen"
origin = [0.0, {y}, 0.0]
rotate = [{tilt_x:e}, {turn:e}, {tilt_z:e}]
shape = {{ kind = "mesh", path = '''{mesh}''' }}
thickness = {thickness:e}
friction = {friction:e}
material = {{ density = {rho:e}, stretch = {stretch:e}, shear = {shear:e}, bending = {bending:e}, damping = {damping:e} }}
[[collider]]
shape = {{ kind = "ground", height = 0.0 }}
response = {{ kind = "restitution", cr = 0.0, friction = {friction:e} }}
[[collider]]
shape = {{ kind = "cylinder", center = [0.0, {TOP}, 0.0], radius = {r:e}, thickness = {TOP} }}
response = {{ kind = "restitution", cr = 0.0, friction = {friction:e} }}
"#,
            d = self.specimen * 100.0,
            p = self.pedestal * 100.0,
            integrator = self.integrator.name(),
            longest = self.longest,
            drag = self.drag,
            tolerance = self.tolerance,
            iterations = self.iterations,
            y = TOP + 0.01,
            thickness = self.thickness,
            rho = m.density,
            stretch = m.stretch,
            shear = m.shear,
            bending = m.bending,
            damping = m.damping,
            friction = self.friction,
            r = 0.5 * self.pedestal,
        );
        let spec = hooke_scene::parse_scene(&text, "drape.toml").context("the drape meter")?;
        let scene = spec
            .build(std::path::Path::new("."))
            .context("the drape meter")?;
        Ok(scene)
    }

    /// Refuses a specimen mesh that is not a flat disc of the meter's size about the axis,
    /// read from its file before any scene is built (a disc on edge would otherwise be
    /// refused as starting inside the pedestal, which says nothing of why).
    fn check_specimen(&self) -> Result<()> {
        let Some(path) = &self.mesh else {
            return Ok(());
        };
        let limit = hooke_scene::MAX_PARTICLES;
        let mesh = match path.to_str().filter(|p| p.starts_with("builtin:")) {
            // A mesh shipped with Hooke, found as a scene finds it.
            Some(name) => hooke_scene::mesh_text(name, std::path::Path::new(""))
                .and_then(|(text, at)| hooke_collide::PolygonMesh::parse(&text, &at, limit)),
            None => hooke_collide::PolygonMesh::load(path, limit),
        }?;
        let used: std::collections::BTreeSet<u32> = mesh
            .faces
            .iter()
            .flat_map(|f| f.corners.iter().copied())
            .collect();
        let points: Vec<hooke_core::Vec3> = used
            .iter()
            .filter_map(|&i| mesh.positions.get(i as usize).copied())
            .collect();
        let reach = points.iter().map(|p| p.x.hypot(p.z)).fold(0.0f64, f64::max);
        let (low, high) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p.y), h.max(p.y))
            });
        let area: f64 = mesh
            .faces
            .iter()
            .map(|f| {
                let at = |k: usize| mesh.positions[f.corners[k] as usize];
                (1..f.corners.len().saturating_sub(1))
                    .map(|k| 0.5 * (at(k) - at(0)).cross(&(at(k + 1) - at(0))).norm())
                    .sum::<f64>()
            })
            .sum();
        let disc = PI * 0.25 * self.specimen * self.specimen;
        if points.is_empty()
            || (reach / (0.5 * self.specimen) - 1.0).abs() > 0.03
            || (area / disc - 1.0).abs() > 0.03
            || high - low > 0.01 * self.specimen
        {
            return Err(crate::Error::input(format!(
                "{}: expected a flat disc {} cm across centred on the origin in the x–z plane; \
                 its farthest vertex is {:.2} cm from the axis, it is {:.2} cm high and its \
                 area is {:.1} cm²",
                path.display(),
                hooke_core::Num(self.specimen * 100.0),
                reach * 100.0,
                (high - low).max(0.0) * 100.0,
                area * 1e4
            )));
        }
        Ok(())
    }

    /// The specimen's own area, m²: its triangles' as built (flat, before any step).
    fn flat_area(&self, scene: &Scene) -> f64 {
        let x = &scene.simulation.particles().x;
        scene.bodies[0]
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| x[i as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    /// Runs one repeat until settled or the longest time, its progress shown as `label`
    /// (none: hidden; Ctrl-C stops it within a step); then measures it.
    pub fn repeat(
        &self,
        material: &Material,
        seed: u64,
        label: Option<&str>,
    ) -> Result<(Repeat, Scene)> {
        let mut scene = self.scene(material, seed)?;
        let flat = self.flat_area(&scene);
        scene.simulation.set_cancel(crate::interrupt::requested);
        let dt = scene.simulation.dt();
        let hold = (self.settle_for / dt).ceil() as u64;
        let read_every = (READ_EVERY / dt).round().max(1.0) as u64;
        let kept = (self.settle_for / READ_EVERY).round() as usize + 1;
        let mut readings: std::collections::VecDeque<f64> = Default::default();
        let mut quiet = 0u64;
        let mut settled = false;
        let bar: Box<dyn crate::progress::Progress> = match label {
            Some(label) => crate::progress::reporter().run_until(label, scene.steps),
            None => Box::new(crate::progress::Hidden),
        };
        let _polling = crate::interrupt::Polling::start();
        for _ in 0..scene.steps {
            crate::interrupt::check(&scene.simulation)?;
            scene.simulation.advance(1).context("the drape test")?;
            // A step an interrupt cut short is no state to measure.
            crate::interrupt::check_after_step(&scene.simulation)?;
            bar.set(scene.simulation.steps());
            let p = scene.simulation.particles();
            let (mut energy, mut mass) = (0.0, 0.0);
            for (v, m) in p.v.iter().zip(&p.mass) {
                energy += 0.5 * m * v.norm_squared();
                mass += m;
            }
            quiet = if energy / mass < self.settle_energy {
                quiet + 1
            } else {
                0
            };
            if scene.simulation.steps() % read_every != 0 {
                continue;
            }
            readings.push_back(self.coefficient(&self.shadow(&scene), flat));
            if readings.len() > kept {
                readings.pop_front();
            }
            let (lo, hi) = readings
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), d| {
                    (l.min(*d), h.max(*d))
                });
            if quiet >= hold && readings.len() == kept && hi - lo <= self.settle_band {
                settled = true;
                break;
            }
        }
        bar.finish();
        let mut repeat = self.measure(&scene, flat, seed, settled);
        // The last second's readings, averaged: a settled specimen still trembles within
        // the band (block descent's inexact solve by about a hundredth in DC).
        // A run shorter than a reading's interval has none: the last state's stands.
        if !readings.is_empty() {
            repeat.dc = readings.iter().sum::<f64>() / readings.len() as f64;
        }
        Ok((repeat, scene))
    }

    /// The shadow of `scene`'s specimen from above, as it is now.
    pub fn shadow(&self, scene: &Scene) -> Shadow {
        let x = &scene.simulation.particles().x;
        Shadow::of(
            x,
            &scene.bodies[0].triangles,
            0.6 * self.specimen,
            self.cell,
        )
    }

    /// The drape coefficient of `shadow` for a specimen of area `flat`:
    /// `(A_shadow − A_pedestal) / (A_specimen − A_pedestal)`.
    fn coefficient(&self, shadow: &Shadow, flat: f64) -> f64 {
        let pedestal = PI * 0.25 * self.pedestal * self.pedestal;
        (shadow.area() - pedestal) / (flat - pedestal)
    }

    /// The meter's view from above: the shadow in grey, one pixel a raster cell, the
    /// pedestal's rim in red, the flat specimen's in blue, and the outline the nodes are
    /// counted on in black.
    pub fn top_view(&self, shadow: &Shadow, outline: &[f64]) -> image::RgbaImage {
        let side = shadow.side as u32;
        let mut image = image::RgbaImage::from_pixel(side, side, image::Rgba([255, 255, 255, 255]));
        for j in 0..shadow.side {
            for i in 0..shadow.side {
                if shadow.covered[j * shadow.side + i] {
                    image.put_pixel(i as u32, j as u32, image::Rgba([150, 150, 160, 255]));
                }
            }
        }
        let half = 0.5 * shadow.side as f64 * shadow.cell;
        let mut dot = |r: f64, angle: f64, colour: [u8; 4]| {
            let (x, z) = (r * angle.cos(), r * angle.sin());
            let (i, j) = ((x + half) / shadow.cell, (z + half) / shadow.cell);
            for (di, dj) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                let (pi, pj) = ((i + di) as i64, (j + dj) as i64);
                if (0..side as i64).contains(&pi) && (0..side as i64).contains(&pj) {
                    image.put_pixel(pi as u32, pj as u32, image::Rgba(colour));
                }
            }
        };
        for k in 0..4000 {
            let a = std::f64::consts::TAU * k as f64 / 4000.0;
            dot(0.5 * self.pedestal, a, [200, 30, 30, 255]);
            dot(0.5 * self.specimen, a, [40, 60, 200, 255]);
            let bin = (k * outline.len() / 4000).min(outline.len() - 1);
            dot(outline[bin], a, [0, 0, 0, 255]);
        }
        image
    }

    /// The coefficient and nodes of `scene`'s specimen (of flat area `flat`) as it is now.
    pub fn measure(&self, scene: &Scene, flat: f64, seed: u64, settled: bool) -> Repeat {
        let shadow = self.shadow(scene);
        let outline = shadow.outline(360);
        Repeat {
            seed,
            dc: self.coefficient(&shadow, flat),
            nodes: nodes(&outline, self.prominence),
            settled,
            time: scene.simulation.time(),
            step: scene.simulation.dt(),
            outline,
        }
    }
}

/// One repeat's reading.
#[derive(Clone, Debug, PartialEq)]
pub struct Repeat {
    /// Its seed.
    pub seed: u64,
    /// The drape coefficient.
    pub dc: f64,
    /// The node count.
    pub nodes: usize,
    /// Whether it settled before the longest time.
    pub settled: bool,
    /// Simulated seconds run.
    pub time: f64,
    /// The step it ran at, seconds.
    pub step: f64,
    /// The outline's radius per degree, metres.
    pub outline: Vec<f64>,
}

/// What the repeats add up to, as labs report it.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// Mean DC.
    pub dc_mean: f64,
    /// DC's sample standard deviation (0 for one repeat).
    pub dc_sd: f64,
    /// Each repeat's node count.
    pub nodes: Vec<usize>,
    /// The most frequent node count (the smaller of a tie).
    pub mode: usize,
    /// Mean DC of the repeats at the most frequent count.
    pub dc_at_mode: f64,
}

impl Summary {
    /// The summary of `repeats` (at least one).
    pub fn of(repeats: &[Repeat]) -> Self {
        let n = repeats.len() as f64;
        let dc_mean = repeats.iter().map(|r| r.dc).sum::<f64>() / n;
        let dc_sd = if repeats.len() > 1 {
            (repeats
                .iter()
                .map(|r| (r.dc - dc_mean).powi(2))
                .sum::<f64>()
                / (n - 1.0))
                .sqrt()
        } else {
            0.0
        };
        let nodes: Vec<usize> = repeats.iter().map(|r| r.nodes).collect();
        let mut counts: Vec<(usize, usize)> = Vec::new();
        for &k in &nodes {
            match counts.iter_mut().find(|(c, _)| *c == k) {
                Some(e) => e.1 += 1,
                None => counts.push((k, 1)),
            }
        }
        counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let mode = counts[0].0;
        let at: Vec<f64> = repeats
            .iter()
            .filter(|r| r.nodes == mode)
            .map(|r| r.dc)
            .collect();
        Self {
            dc_mean,
            dc_sd,
            nodes,
            mode,
            dc_at_mode: at.iter().sum::<f64>() / at.len() as f64,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Summaries as labs give them: the most frequent count (the smaller of a tie) and
    /// the mean DC of the repeats at it.
    #[test]
    fn the_summary_reports_the_mode_and_its_coefficient() {
        let r = |dc: f64, nodes: usize| Repeat {
            seed: 0,
            dc,
            nodes,
            settled: true,
            time: 1.0,
            step: 1e-5,
            outline: Vec::new(),
        };
        let s = Summary::of(&[r(0.40, 8), r(0.44, 9), r(0.42, 9), r(0.38, 8), r(0.50, 10)]);
        assert_eq!(s.nodes, [8, 9, 9, 8, 10]);
        assert_eq!(s.mode, 8);
        assert!((s.dc_at_mode - 0.39).abs() < 1e-12);
        assert!((s.dc_mean - 0.428).abs() < 1e-12);
        let sd = ((0.028f64.powi(2)
            + 0.012f64.powi(2)
            + 0.008f64.powi(2)
            + 0.048f64.powi(2)
            + 0.072f64.powi(2))
            / 4.0)
            .sqrt();
        assert!((s.dc_sd - sd).abs() < 1e-12, "{} {sd}", s.dc_sd);
    }
}
