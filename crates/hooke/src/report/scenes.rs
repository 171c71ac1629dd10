//! The built-in scenes as pictures and contacts: each still beside its golden image with
//! the pixels that differ, and on every frame up to the still the cloth's crossings (none
//! allowed) and its smallest gap to a collider.

use super::crossings::{self, Tri};
use super::folder::Pending;
use super::pixels::compare;
use super::references::References;
use crate::Result;
use crate::image_out::View;
use crate::quantity::ColorBy;
use crate::stills::{still_steps, still_view};
use hooke_core::Vec3;
use hooke_core::contact::proximity::point_triangle;
use hooke_scene::{Overrides, Scene};
use serde::Serialize;
use std::path::Path;

/// Scenes quick enough for `--quick`.
const QUICK: [&str; 3] = ["single-spring", "chain", "jello-cube"];

/// One scene's still and contacts.
#[derive(Serialize)]
pub(crate) struct SceneCheck {
    pub(crate) name: String,
    /// The still's simulated time, s.
    pub(crate) time: f64,
    /// Pixels differing from the golden by more than the tolerance, of all its pixels.
    pub(crate) differing_pixels: usize,
    pub(crate) pixels: usize,
    /// Frames checked for contacts.
    pub(crate) frames: u64,
    /// Cloth–collider and cloth–cloth crossing pairs, summed over the frames.
    pub(crate) collider_crossings: usize,
    pub(crate) cloth_crossings: usize,
    /// The smallest distance from a surface particle to a collider's surface over the
    /// frames, m (`None`: no surface or no collider).
    pub(crate) min_gap: Option<f64>,
    /// Files beside the page.
    pub(crate) still: String,
    pub(crate) golden: String,
    pub(crate) diff: String,
    /// A cloth scene's still coloured by strain, its largest strain (%) and what a column of
    /// its cloth hanging from one structural spring stretches that spring by (%).
    pub(crate) strain: Option<StrainPicture>,
}

/// A cloth scene's strain picture and figures.
#[derive(Serialize)]
pub(crate) struct StrainPicture {
    pub(crate) file: String,
    pub(crate) largest: f64,
    pub(crate) weight: f64,
}

/// What the weight of a column of the cloth stretches the structural spring it hangs from
/// by, in percent: `(n − 1) m g / (ks L)` for the longest column of `n` particles of mass
/// `m` on springs of stiffness `ks` and rest length `L` (the mean over the structural
/// springs). The scale of the stretch the cloth's own weight gives, where a pinned corner
/// carries more (it holds more than one column).
fn weight_strain(scene: &Scene) -> Option<f64> {
    let model = scene.simulation.model();
    let p = scene.simulation.particles();
    let g = model.gravity.norm();
    let mut best: Option<f64> = None;
    for body in &scene.bodies {
        let hooke_scene::Topology::Grid([a, b]) = body.topology else {
            continue;
        };
        let springs: Vec<_> = model
            .springs
            .iter()
            .filter(|s| {
                s.kind == hooke_core::SpringKind::Structural && body.range.contains(&(s.i as usize))
            })
            .collect();
        if springs.is_empty() {
            continue;
        }
        let ks = springs.iter().map(|s| s.ks).sum::<f64>() / springs.len() as f64;
        let rest = springs.iter().map(|s| s.rest).sum::<f64>() / springs.len() as f64;
        let mass = p.mass[body.range.clone()].iter().sum::<f64>() / body.range.len() as f64;
        let n = a.max(b) as f64;
        let e = (n - 1.0) * mass * g / (ks * rest) * 100.0;
        best = Some(best.map_or(e, |m: f64| m.max(e)));
    }
    best
}

/// The cloth's triangles now, with their corners.
fn cloth(scene: &Scene) -> Vec<(Tri, [u32; 3])> {
    let x = &scene.simulation.particles().x;
    scene
        .bodies
        .iter()
        .flat_map(|b| b.triangles.iter())
        .map(|t| (t.map(|i| x[i as usize]), *t))
        .collect()
}

/// How near a collider triangle a particle must be for its distance to count, m.
const GAP_REACH: f64 = 0.05;

/// A collider triangle with its box grown by [`GAP_REACH`], computed once per scene.
struct Near {
    corners: Tri,
    lo: Vec3,
    hi: Vec3,
}

impl Near {
    fn new(corners: &Tri) -> Self {
        let t = corners;
        Self {
            corners: *t,
            lo: t[0].inf(&t[1]).inf(&t[2]).add_scalar(-GAP_REACH),
            hi: t[0].sup(&t[1]).sup(&t[2]).add_scalar(GAP_REACH),
        }
    }
}

/// The smallest distance from a surface particle to a collider triangle near it.
fn min_gap(scene: &Scene, colliders: &[Near]) -> Option<f64> {
    let x = &scene.simulation.particles().x;
    let mut best: Option<f64> = None;
    for body in &scene.bodies {
        if body.triangles.is_empty() {
            continue;
        }
        for p in &x[body.range.clone()] {
            for near in colliders {
                if (0..3).any(|k| p[k] < near.lo[k] || p[k] > near.hi[k]) {
                    continue;
                }
                let t = &near.corners;
                let w = point_triangle(p, &t[0], &t[1], &t[2]);
                let q: Vec3 = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
                let d = (p - q).norm();
                best = Some(best.map_or(d, |b| b.min(d)));
            }
        }
    }
    best
}

impl SceneCheck {
    /// Whether the still matches its golden.
    pub(crate) fn matches_golden(&self) -> bool {
        self.differing_pixels <= super::pixels::allowed(self.pixels)
    }

    /// Crossing pairs of all kinds, summed over the frames.
    pub(crate) fn crossings(&self) -> usize {
        self.collider_crossings + self.cloth_crossings
    }
}

/// Runs built-in `name` to its still, checking contacts on every frame, and compares the
/// still with its golden; the images go to `dir`.
fn check(name: &str, golden: &[u8], files: &mut Pending) -> Result<SceneCheck> {
    let mut scene = crate::source::build(name, &Overrides::default())?;
    let steps = still_steps(name, &scene);
    let colliders: Vec<Tri> = crate::export::collider_triangles(&scene)
        .into_iter()
        .flat_map(|(_, t)| t)
        .collect();
    let near: Vec<Near> = colliders.iter().map(Near::new).collect();
    let surfaces = scene.bodies.iter().any(|b| !b.triangles.is_empty());
    let (mut frames, mut against, mut among, mut gap) = (0, 0, 0, None::<f64>);
    let mut look = |scene: &Scene| {
        frames += 1;
        if surfaces {
            let (a, b) = crossings::count(&cloth(scene), &colliders);
            against += a;
            among += b;
            if let Some(g) = min_gap(scene, &near) {
                gap = Some(gap.map_or(g, |m| m.min(g)));
            }
        }
    };
    look(&scene);
    let every = scene.every;
    let mut done = 0;
    while done < steps {
        let n = every.min(steps - done);
        crate::driver::advance(&mut scene, n)?;
        done += n;
        look(&scene);
    }
    let view = still_view(
        name,
        &View {
            size: (320, 240),
            ..View::default()
        },
    );
    let actual = view.pixels(&scene, &view.camera(&scene));
    let golden = image::load_from_memory(golden)?.to_rgba8();
    let (bad, diff) = if golden.dimensions() == actual.dimensions() {
        compare(&golden, &actual)
    } else {
        (actual.len() / 4, actual.clone())
    };
    let file = |kind: &str| super::folder::scene_file(name, kind);
    for (kind, image) in [("still", &actual), ("golden", &golden), ("diff", &diff)] {
        let bytes = crate::image_out::png_bytes(Path::new(&file(kind)), image)?;
        files.add(file(kind), bytes);
    }
    let strain = match weight_strain(&scene) {
        Some(weight) => {
            let view = View {
                color: ColorBy::Strain,
                ..view.clone()
            };
            let picture = view.pixels(&scene, &view.camera(&scene));
            let bytes = crate::image_out::png_bytes(Path::new(&file("strain")), &picture)?;
            files.add(file("strain"), bytes);
            let cloth: Vec<usize> = scene
                .bodies
                .iter()
                .filter(|b| matches!(b.topology, hooke_scene::Topology::Grid(_)))
                .flat_map(|b| b.range.clone())
                .collect();
            let values = ColorBy::Strain.values(&scene).unwrap_or_default();
            let largest = cloth
                .iter()
                .filter_map(|&i| values.get(i))
                .fold(f64::NEG_INFINITY, |m, v| m.max(*v));
            Some(StrainPicture {
                file: file("strain"),
                largest,
                weight,
            })
        }
        None => None,
    };
    Ok(SceneCheck {
        name: name.to_string(),
        time: scene.simulation.time(),
        differing_pixels: bad,
        pixels: (actual.width() * actual.height()) as usize,
        frames,
        collider_crossings: against,
        cloth_crossings: among,
        min_gap: gap,
        still: file("still"),
        golden: file("golden"),
        diff: file("diff"),
        strain,
    })
}

/// The scenes checked: every built-in, or the quick ones.
pub(crate) fn names(quick: bool) -> Vec<&'static str> {
    hooke_scene::builtin::BUILTINS
        .iter()
        .map(|(n, _)| *n)
        .filter(|n| !quick || QUICK.contains(n))
        .collect()
}

/// Every scene of [`names`], `tick` after each.
pub(crate) fn checks(
    quick: bool,
    references: &References,
    files: &mut Pending,
    tick: &mut dyn FnMut(),
) -> Result<Vec<SceneCheck>> {
    let mut out = Vec::new();
    for name in names(quick) {
        let golden = references.golden(name)?;
        out.push(check(name, &golden, files)?);
        tick();
    }
    Ok(out)
}
