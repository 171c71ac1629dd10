//! The rasterizer: tiles of samples kept in cache, each filled with every primitive that
//! touches it and resolved straight into output pixels, so no full-size supersampled frame
//! is ever allocated.
//!
//! The pipeline: primitive setup in parallel over the draw list (projection, fixed-point
//! corners, sample rectangles); binning into tiles in fixed chunks; then in parallel over
//! tiles, scan conversion into a depth + primitive-id buffer and a resolve that shades each
//! distinct primitive of a pixel once. Every tile sees its primitives in draw-list order and
//! no two tiles share a pixel, so the picture is the same bits whatever the thread count.
//! Attributes are interpolated perspective-correctly: barycentrics are weighted by `1/w`
//! and renormalised (Low, "Perspective-Correct Interpolation", 2002).

use crate::bins::{Bins, Grid};
use crate::camera::Camera;
use crate::draw_list::{DrawList, Rgb};
use crate::setup::{Frame, LineSetup, PointSetup, Rect, TriSetup};
use crate::shading::Shading;
use crate::tile::{EMPTY, Samples};
use nalgebra::Vector3;
use rayon::prelude::*;

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Samples per pixel along each axis: 2 is 4× supersampling (the default for stills).
    pub supersample: u32,
    /// Background at the top and bottom of the image.
    pub background: [Rgb; 2],
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 800,
            height: 600,
            supersample: 2,
            background: [[0.80, 0.86, 0.93], [0.97, 0.97, 0.98]],
        }
    }
}

/// Tile side in output pixels: with 4× supersampling a tile's depth and id buffers take
/// 128 KiB, which stays in a core's L2 cache.
pub const TILE: u32 = 64;

/// Everything the resolve needs to shade a sample's primitive.
struct Prepared<'a> {
    list: &'a DrawList,
    tris: &'a [Option<TriSetup>],
    lines: &'a [Option<LineSetup>],
    points: &'a [Option<PointSetup>],
    shading: Shading,
    options: &'a RenderOptions,
    ss: u32,
}

/// What a primitive shows at one point.
enum Surface {
    /// An unlit colour: background and lines.
    Flat(Rgb),
    /// A base colour lit with a normal.
    Lit(Vector3<f64>, Rgb),
}

impl Prepared<'_> {
    /// What primitive `id` shows at the sample-space point `p`.
    fn surface(&self, id: u32, p: (f64, f64)) -> Surface {
        let id = id as usize;
        let (nt, nl) = (self.tris.len(), self.lines.len());
        if id < nt {
            let Some(s) = &self.tris[id] else {
                return Surface::Flat([0.0; 3]);
            };
            if s.tiny {
                return Surface::Lit(s.normal, s.color);
            }
            let t = &self.list.triangles[s.src as usize];
            let w = s.weights(p);
            Surface::Lit(t.n[0] * w[0] + t.n[1] * w[1] + t.n[2] * w[2], t.color)
        } else if id < nt + nl {
            Surface::Flat(self.lines[id - nt].map_or([0.0; 3], |l| l.color))
        } else {
            let Some(s) = &self.points[id - nt - nl] else {
                return Surface::Flat([0.0; 3]);
            };
            let (u, v) = ((p.0 - s.c.0) / s.radius, (s.c.1 - p.1) / s.radius);
            let r2 = (u * u + v * v).min(1.0);
            let n = self.shading.right * u + self.shading.up * v
                - self.shading.forward * (1.0 - r2).sqrt();
            Surface::Lit(n, s.color)
        }
    }

    fn background(&self, row: u32) -> Rgb {
        let t = (row as f32 + 0.5) / self.options.height as f32;
        let [top, bottom] = self.options.background;
        [0, 1, 2].map(|c| top[c] * (1.0 - t) + bottom[c] * t)
    }

    /// The first output pixel `(x, y)` of a tile of samples and its size in pixels.
    fn pixels_of(&self, area: &Rect) -> ((u32, u32), (u32, u32)) {
        let ss = self.ss;
        let first = (area.x0 / ss, area.y0 / ss);
        (first, ((area.x1 - area.x0) / ss, (area.y1 - area.y0) / ss))
    }

    /// The background of a tile that no primitive touches, row-major over the tile: what
    /// [`Prepared::resolve`] gives for it, without clearing and reading its samples (most
    /// tiles of a still where the subject fills a third of the frame).
    fn background_tile(&self, area: &Rect, out: &mut Vec<u8>) {
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
    fn resolve(&self, s: &Samples, out: &mut Vec<u8>) {
        let ss = self.ss;
        let ((px0, py0), (w, h)) = self.pixels_of(&s.area);
        let weight = 1.0 / (ss * ss) as f32;
        out.clear();
        out.resize((w * h * 4) as usize, 0);
        // Distinct primitives of one pixel and their sample counts (at most 16 samples), and
        // its distinct lit materials: reused from pixel to pixel (only the first `distinct`
        // or `materials` entries are read), as clearing 16 materials per edge pixel cost a
        // tenth of a cloth-256 frame.
        let mut ids = [(0u32, 0u32); 16];
        let mut lit: [(Rgb, Vector3<f64>, u32); 16] = [([0.0; 3], Vector3::zeros(), 0); 16];
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
                    match self.surface(ids[0].0, centre) {
                        Surface::Flat(c) => c,
                        Surface::Lit(n, c) => self.shading.shade(n, c),
                    }
                } else {
                    // Samples of one base colour are lit once with their summed normals:
                    // where a smooth mesh's triangles are pixel-sized, a pixel shades once
                    // per material rather than once per triangle, and looks the same.
                    let mut sum = [0.0f32; 3];
                    let mut materials = 0;
                    for &(id, count) in &ids[..distinct] {
                        let surface = if id == EMPTY {
                            Surface::Flat(background)
                        } else {
                            self.surface(id, centre)
                        };
                        match surface {
                            Surface::Flat(c) => {
                                for k in 0..3 {
                                    sum[k] += c[k] * count as f32;
                                }
                            }
                            Surface::Lit(n, c) => {
                                match lit[..materials].iter_mut().find(|m| m.0 == c) {
                                    Some(m) => {
                                        m.1 += n * count as f64;
                                        m.2 += count;
                                    }
                                    None => {
                                        lit[materials] = (c, n * count as f64, count);
                                        materials += 1;
                                    }
                                }
                            }
                        }
                    }
                    for (c, n, count) in &lit[..materials] {
                        let c = self.shading.shade(*n, *c);
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
fn rgba8(c: Rgb) -> [u8; 4] {
    // Truncating `v + 0.5` rounds: `f32::round` is a libm call per channel. The value is
    // in [0.5, 255.5] (or NaN, which gives 0 either way), so going through i32 skips the
    // saturating u8 conversion's extra tests.
    let channel = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as i32 as u8;
    [channel(c[0]), channel(c[1]), channel(c[2]), 255]
}

/// Renders `list` seen by `camera` into an RGBA8 image of `width × height` pixels, row-major.
///
/// A one-off: [`Renderer`] keeps its buffers from frame to frame.
pub fn render(list: &DrawList, camera: &Camera, options: &RenderOptions) -> Vec<u8> {
    Renderer::default().render(list, camera, options)
}

/// A rasterizer that keeps its per-primitive buffers between frames, so an animation or a
/// viewer does not allocate (and the kernel does not zero) hundreds of megabytes per frame.
#[derive(Default)]
pub struct Renderer {
    /// Set-up primitives by draw-list index; `None` where culled.
    tris: Vec<Option<TriSetup>>,
    lines: Vec<Option<LineSetup>>,
    points: Vec<Option<PointSetup>>,
    tri_bins: Bins,
    line_bins: Bins,
    point_bins: Bins,
    /// Each tile's resolved pixels.
    tiles: Vec<Vec<u8>>,
}

/// Sets up every primitive of `list` into `out` (same length, reusing its memory).
fn set_up<P: Sync, S: Send>(
    out: &mut Vec<Option<S>>,
    list: &[P],
    f: impl Fn(usize, &P) -> Option<S> + Sync,
) {
    out.resize_with(list.len(), || None);
    out.par_iter_mut()
        .zip(list.par_iter())
        .enumerate()
        .for_each(|(i, (slot, p))| *slot = f(i, p));
}

impl Renderer {
    /// Renders `list` seen by `camera` into an RGBA8 image of `width × height` pixels,
    /// row-major. The pixels depend only on the arguments, never on earlier frames.
    pub fn render(&mut self, list: &DrawList, camera: &Camera, options: &RenderOptions) -> Vec<u8> {
        let ss = options.supersample.max(1);
        let (w, h) = (options.width * ss, options.height * ss);
        let frame = Frame::new(camera, w, h);
        let per_pixel = ss as f64;
        set_up(&mut self.tris, &list.triangles, |i, t| {
            TriSetup::new(&frame, t, i as u32)
        });
        set_up(&mut self.lines, &list.lines, |_, l| {
            LineSetup::new(&frame, l, per_pixel)
        });
        set_up(&mut self.points, &list.points, |_, p| {
            PointSetup::new(&frame, p, per_pixel)
        });
        let grid = Grid::new(w, h, TILE * ss);
        self.tri_bins.fill(&self.tris, |t| t.rect, &grid);
        self.line_bins.fill(&self.lines, |l| l.rect, &grid);
        self.point_bins.fill(&self.points, |p| p.rect, &grid);
        let prepared = Prepared {
            list,
            tris: &self.tris,
            lines: &self.lines,
            points: &self.points,
            shading: Shading::new(camera),
            options,
            ss,
        };
        let (nt, nl) = (self.tris.len() as u32, self.lines.len() as u32);
        let (tri_bins, line_bins, point_bins) = (&self.tri_bins, &self.line_bins, &self.point_bins);

        self.tiles.resize_with(grid.count(), Vec::new);
        self.tiles.par_iter_mut().enumerate().for_each_init(
            || Samples::new(grid.side),
            |samples, (t, pixels)| {
                let (tx, ty) = (t as u32 % grid.across, t as u32 / grid.across);
                let area = Rect {
                    x0: tx * grid.side,
                    y0: ty * grid.side,
                    x1: ((tx + 1) * grid.side).min(w),
                    y1: ((ty + 1) * grid.side).min(h),
                };
                let bins = [tri_bins, line_bins, point_bins];
                if bins.iter().all(|b| b.tile(t).next().is_none()) {
                    prepared.background_tile(&area, pixels);
                    return;
                }
                samples.reset(area);
                // Binned primitives are the set-up ones: the `if let` never skips.
                for id in tri_bins.tile(t) {
                    if let Some(s) = &prepared.tris[id as usize] {
                        samples.triangle(s, id);
                    }
                }
                for id in line_bins.tile(t) {
                    if let Some(s) = &prepared.lines[id as usize] {
                        samples.line(s, nt + id);
                    }
                }
                for id in point_bins.tile(t) {
                    if let Some(s) = &prepared.points[id as usize] {
                        samples.point(s, nt + nl + id);
                    }
                }
                prepared.resolve(samples, pixels);
            },
        );

        let (width, tile) = (options.width as usize, TILE as usize);
        let mut out = vec![0u8; width * options.height as usize * 4];
        for (t, pixels) in self.tiles.iter().enumerate() {
            let (tx, ty) = (t % grid.across as usize, t / grid.across as usize);
            let tile_width = tile.min(width - tx * tile);
            for (r, row) in pixels.chunks(tile_width * 4).enumerate() {
                let start = ((ty * tile + r) * width + tx * tile) * 4;
                out[start..start + row.len()].copy_from_slice(row);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::draw_list::{Line, Point};

    fn scene() -> DrawList {
        let mut list = DrawList::default();
        for k in 0..200 {
            let a = k as f64 * 0.1;
            let p = |r: f64, y: f64| Vector3::new(r * a.cos(), y, r * a.sin());
            list.flat(
                [p(0.2, 0.0), p(1.0, 0.3 + 0.01 * k as f64), p(0.6, 1.0)],
                [0.2 + (k % 7) as f32 * 0.1, 0.5, 0.3],
            );
        }
        list.lines.push(Line {
            a: Vector3::new(-1.0, 0.0, 0.0),
            b: Vector3::new(1.0, 1.0, 0.0),
            color: [0.0; 3],
            width: 2.0,
        });
        list.points.push(Point {
            p: Vector3::new(0.0, 0.5, 0.0),
            color: [1.0, 0.0, 0.0],
            radius: 5.0,
        });
        list
    }

    #[test]
    fn pixels_do_not_depend_on_the_thread_count() {
        let list = scene();
        let camera = Camera::framing(
            Vector3::new(-1.0, 0.0, -1.0),
            Vector3::new(1.0, 3.0, 1.0),
            30.0,
            20.0,
        );
        let options = RenderOptions {
            width: 160,
            height: 120,
            ..RenderOptions::default()
        };
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| render(&list, &camera, &options))
        };
        let one = on(1);
        assert_eq!(one, on(2));
        assert_eq!(one, on(3));
        // And the picture is not empty: some pixels differ from the background.
        let background = &one[..4];
        assert!(one.chunks(4).filter(|p| p != &background).count() > 1000);
    }

    #[test]
    fn nearer_triangles_hide_farther_ones() {
        let mut list = DrawList::default();
        let quad = |list: &mut DrawList, z: f64, color| {
            let p = |x: f64, y: f64| Vector3::new(x, y, z);
            list.flat([p(-1.0, -1.0), p(1.0, -1.0), p(1.0, 1.0)], color);
            list.flat([p(-1.0, -1.0), p(1.0, 1.0), p(-1.0, 1.0)], color);
        };
        // Drawn far-after-near, so only the depth test can put red in front.
        quad(&mut list, 0.5, [1.0, 0.0, 0.0]);
        quad(&mut list, -0.5, [0.0, 0.0, 1.0]);
        let camera = Camera {
            target: Vector3::zeros(),
            distance: 5.0,
            yaw: 0.0,
            pitch: 0.0,
            fov_y: 40.0,
        };
        let px = render(
            &list,
            &camera,
            &RenderOptions {
                width: 32,
                height: 32,
                ..RenderOptions::default()
            },
        );
        let centre = &px[(16 * 32 + 16) * 4..][..3];
        assert!(
            centre[0] > 50 && centre[2] < 10,
            "centre pixel {centre:?} should be the red, nearer quad"
        );
    }
}
