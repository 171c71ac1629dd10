//! The downsampling: shading each tile's samples into output pixels, one shade per distinct
//! primitive (or lit material) of a pixel, averaged over its samples.

use crate::draw_list::{DrawList, Rgb};
use crate::options::RenderOptions;
use crate::setup::{LineSetup, PointSetup, Rect, TriSetup};
use crate::shading::Shading;
use crate::shadow::ShadowMap;
use crate::tile::{EMPTY, Samples};
use nalgebra::Vector3;

/// Everything the downsampling needs to shade a sample's primitive: the set-up primitives by
/// draw-list index, the lighting, and the samples per pixel along each axis.
pub(crate) struct Downsampler<'a> {
    pub list: &'a DrawList,
    /// [`Renderer::mesh_start`].
    pub mesh_start: &'a [usize],
    pub tris: &'a [Option<TriSetup>],
    pub lines: &'a [Option<LineSetup>],
    pub points: &'a [Option<PointSetup>],
    pub shading: Shading,
    /// The key light's shadow map, when shadows are drawn.
    pub shadow: Option<ShadowMap>,
    pub options: &'a RenderOptions,
    /// Samples per pixel along each axis.
    pub supersample: u32,
}

/// A lit material of one pixel: its colour, summed normal, sample count and summed shares
/// of the key and ambient light.
type Material = (Rgb, Vector3<f64>, u32, (f32, f32));

/// A triangle's colour: one, or one per corner to interpolate.
enum Corners {
    One(Rgb),
    Three([Rgb; 3]),
}

/// What a primitive shows at one point.
enum Surface {
    /// An unlit colour: background and lines.
    Flat(Rgb),
    /// A base colour lit with a normal, and the shares of the key light and of the ambient
    /// light it receives.
    Lit(Vector3<f64>, Rgb, (f32, f32)),
}

impl Downsampler<'_> {
    /// What primitive `id` shows at the sample-space point `p`. `shadow` is the share of
    /// the key light found for another primitive of the same pixel, if any: within a pixel
    /// the shadow map's filter (five texels wide) does not change, and a pixel where a
    /// cloth's small triangles meet looks it up once rather than once per triangle.
    fn surface(&self, id: u32, p: (f64, f64), shadow: &mut Option<(f32, f32)>) -> Surface {
        let id = id as usize;
        let (tris, lines) = (self.tris.len(), self.lines.len());
        if id < tris {
            let Some(s) = &self.tris[id] else {
                return Surface::Flat([0.0; 3]);
            };
            let (n, q, colors) = self.corners(s.src as usize);
            let w = if s.tiny { [1.0 / 3.0; 3] } else { s.weights(p) };
            let color = match colors {
                Corners::One(c) => c,
                Corners::Three(c) => {
                    let w = w.map(|w| w as f32);
                    [0, 1, 2].map(|k| c[0][k] * w[0] + c[1][k] * w[1] + c[2][k] * w[2])
                }
            };
            let normal = if s.tiny {
                s.normal
            } else {
                n[0] * w[0] + n[1] * w[1] + n[2] * w[2]
            };
            let light = match (&self.shadow, *shadow) {
                (None, _) => (1.0, 1.0),
                (Some(_), Some(found)) => found,
                (Some(map), None) => {
                    let found = map.light(&(q[0] * w[0] + q[1] * w[1] + q[2] * w[2]), &normal);
                    *shadow = Some(found);
                    found
                }
            };
            Surface::Lit(normal, color, light)
        } else if id < tris + lines {
            Surface::Flat(self.lines[id - tris].map_or([0.0; 3], |l| l.color))
        } else {
            let Some(s) = &self.points[id - tris - lines] else {
                return Surface::Flat([0.0; 3]);
            };
            let (u, v) = ((p.0 - s.c.0) / s.radius, (s.c.1 - p.1) / s.radius);
            let r2 = (u * u + v * v).min(1.0);
            let n = self.shading.right * u + self.shading.up * v
                - self.shading.forward * (1.0 - r2).sqrt();
            Surface::Lit(n, s.color, (1.0, 1.0))
        }
    }

    /// The corner normals, corner positions and colours of set-up triangle `id`: a
    /// mesh's, or after the meshes' the list's own. Only triangles that were set up are
    /// asked for, and set-up checked their corners.
    fn corners(&self, id: usize) -> ([Vector3<f64>; 3], [Vector3<f64>; 3], Corners) {
        let meshes_end = self.mesh_start[self.mesh_start.len() - 1];
        if id < meshes_end {
            let m = self.mesh_start.partition_point(|&start| start <= id) - 1;
            let mesh = &self.list.meshes[m];
            let corners = mesh.triangles[id - self.mesh_start[m]];
            let colors = if mesh.colors.is_empty() {
                Corners::One(mesh.color)
            } else {
                Corners::Three(
                    corners.map(|c| mesh.colors.get(c as usize).copied().unwrap_or(mesh.color)),
                )
            };
            (
                corners.map(|c| mesh.normals[c as usize]),
                corners.map(|c| mesh.positions[c as usize]),
                colors,
            )
        } else {
            let t = &self.list.triangles[id - meshes_end];
            (t.n, t.p, Corners::One(t.color))
        }
    }

    pub fn background(&self, row: u32) -> Rgb {
        let t = (row as f32 + 0.5) / self.options.height as f32;
        let [top, bottom] = self.options.background;
        [0, 1, 2].map(|c| top[c] * (1.0 - t) + bottom[c] * t)
    }

    /// The first output pixel `(x, y)` of a tile of samples and its size in pixels.
    fn pixels_of(&self, area: &Rect) -> ((u32, u32), (u32, u32)) {
        let ss = self.supersample; // samples per pixel along each axis
        let first = (area.x0 / ss, area.y0 / ss);
        (first, ((area.x1 - area.x0) / ss, (area.y1 - area.y0) / ss))
    }

    /// The background of a tile that no primitive touches, row-major over the tile: what
    /// [`Downsampler::downsample`] gives for it, without clearing and reading its samples (most
    /// tiles of a still where the subject fills a third of the frame).
    pub fn background_tile(&self, area: &Rect, out: &mut Vec<u8>) {
        let ((_, py0), (w, h)) = self.pixels_of(area);
        out.clear();
        out.resize((w * h * 4) as usize, 0);
        for (y, pixels) in (0..h).zip(out.chunks_exact_mut((w * 4) as usize)) {
            let pixel = rgba8(self.background(py0 + y));
            for p in pixels.chunks_exact_mut(4) {
                p.copy_from_slice(&pixel);
            }
        }
    }

    /// Shades and averages the tile's samples into RGBA8 pixels, row-major over the tile.
    pub fn downsample(&self, s: &Samples, out: &mut Vec<u8>) {
        let ss = self.supersample; // samples per pixel along each axis
        let ((px0, py0), (w, h)) = self.pixels_of(&s.area);
        let weight = 1.0 / (ss * ss) as f32;
        out.clear();
        out.resize((w * h * 4) as usize, 0);
        // Distinct primitives of one pixel and their sample counts (at most 16 samples), and
        // its distinct lit materials: reused from pixel to pixel (only the first `distinct`
        // or `materials` entries are read), as clearing 16 materials per edge pixel cost a
        // tenth of a cloth-256 frame.
        let mut ids = [(0u32, 0u32); 16];
        let mut lit: [Material; 16] = [([0.0; 3], Vector3::zeros(), 0, (0.0, 0.0)); 16];
        for (y, pixels) in (0..h).zip(out.chunks_exact_mut((w * 4) as usize)) {
            let background = self.background(py0 + y);
            let row = s.index(s.area.x0, s.area.y0 + y * ss);
            for (x, pixel) in (0..w).zip(pixels.chunks_exact_mut(4)) {
                let first = row + (x * ss) as usize;
                let mut distinct = 0;
                for sy in 0..ss as usize {
                    for sx in 0..ss as usize {
                        let id = s.id[first + sy * s.stride + sx];
                        match ids[..distinct].iter_mut().find(|(i, _)| *i == id) {
                            Some((_, count)) => *count += 1,
                            None => {
                                ids[distinct] = (id, 1);
                                distinct += 1;
                            }
                        }
                    }
                }
                let centre = (
                    ((px0 + x) * ss) as f64 + ss as f64 * 0.5,
                    ((py0 + y) * ss) as f64 + ss as f64 * 0.5,
                );
                let c = if distinct == 1 && ids[0].0 == EMPTY {
                    background
                } else if distinct == 1 {
                    match self.surface(ids[0].0, centre, &mut None) {
                        Surface::Flat(c) => c,
                        Surface::Lit(n, c, light) => self.shading.shade(n, c, light),
                    }
                } else {
                    // Samples of one base colour are lit once with their summed normals:
                    // where a smooth mesh's triangles are pixel-sized, a pixel shades once
                    // per material rather than once per triangle, and looks the same.
                    let mut sum = [0.0f32; 3];
                    let mut materials = 0;
                    let mut shadow = None;
                    for &(id, count) in &ids[..distinct] {
                        let surface = if id == EMPTY {
                            Surface::Flat(background)
                        } else {
                            self.surface(id, centre, &mut shadow)
                        };
                        match surface {
                            Surface::Flat(c) => {
                                for k in 0..3 {
                                    sum[k] += c[k] * count as f32;
                                }
                            }
                            Surface::Lit(n, c, light) => {
                                match lit[..materials].iter_mut().find(|m| m.0 == c) {
                                    Some(m) => {
                                        m.1 += n * count as f64;
                                        m.2 += count;
                                        m.3.0 += light.0 * count as f32;
                                        m.3.1 += light.1 * count as f32;
                                    }
                                    None => {
                                        let k = count as f32;
                                        lit[materials] = (
                                            c,
                                            n * count as f64,
                                            count,
                                            (light.0 * k, light.1 * k),
                                        );
                                        materials += 1;
                                    }
                                }
                            }
                        }
                    }
                    for (c, n, count, light) in &lit[..materials] {
                        let k = *count as f32;
                        let c = self.shading.shade(*n, *c, (light.0 / k, light.1 / k));
                        for k in 0..3 {
                            sum[k] += c[k] * *count as f32;
                        }
                    }
                    sum.map(|v| v * weight)
                };
                pixel.copy_from_slice(&rgba8(c));
            }
        }
    }
}

/// An opaque RGBA8 pixel of colour `c`, each channel clamped to `[0, 1]`.
#[inline]
pub(crate) fn rgba8(c: Rgb) -> [u8; 4] {
    // Truncating `v + 0.5` rounds: `f32::round` is a libm call per channel. The value is
    // in [0.5, 255.5] (or NaN, which gives 0 either way), so going through i32 skips the
    // saturating u8 conversion's extra tests.
    let channel = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as i32 as u8;
    [channel(c[0]), channel(c[1]), channel(c[2]), 255]
}
