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
    tris: Vec<TriSetup>,
    lines: Vec<LineSetup>,
    points: Vec<PointSetup>,
    shading: Shading,
    options: &'a RenderOptions,
    ss: u32,
}

impl Prepared<'_> {
    /// The colour of primitive `id` at the sample-space point `p`.
    fn shade(&self, id: u32, p: (f64, f64)) -> Rgb {
        let id = id as usize;
        let (nt, nl) = (self.tris.len(), self.lines.len());
        if id < nt {
            let s = &self.tris[id];
            let t = &self.list.triangles[s.src as usize];
            let w = s.weights(p);
            self.shading
                .shade(t.n[0] * w[0] + t.n[1] * w[1] + t.n[2] * w[2], t.color)
        } else if id < nt + nl {
            self.lines[id - nt].color
        } else {
            let s = &self.points[id - nt - nl];
            let (u, v) = ((p.0 - s.c.0) / s.radius, (s.c.1 - p.1) / s.radius);
            let r2 = (u * u + v * v).min(1.0);
            let n = self.shading.right * u + self.shading.up * v
                - self.shading.forward * (1.0 - r2).sqrt();
            self.shading.shade(n, s.color)
        }
    }

    fn background(&self, row: u32) -> Rgb {
        let t = (row as f32 + 0.5) / self.options.height as f32;
        let [top, bottom] = self.options.background;
        [0, 1, 2].map(|c| top[c] * (1.0 - t) + bottom[c] * t)
    }

    /// Shades and averages the tile's samples into RGBA8 pixels, row-major over the tile.
    fn resolve(&self, s: &Samples) -> Vec<u8> {
        let ss = self.ss;
        let (px0, py0) = (s.area.x0 / ss, s.area.y0 / ss);
        let (w, h) = ((s.area.x1 - s.area.x0) / ss, (s.area.y1 - s.area.y0) / ss);
        let n = (ss * ss) as f32;
        let mut out = vec![0u8; (w * h * 4) as usize];
        let mut ids: Vec<(u32, u32)> = Vec::with_capacity((ss * ss) as usize);
        for y in 0..h {
            let background = self.background(py0 + y);
            for x in 0..w {
                ids.clear();
                for sy in 0..ss {
                    for sx in 0..ss {
                        let id = s.id[s.index(s.area.x0 + x * ss + sx, s.area.y0 + y * ss + sy)];
                        match ids.iter_mut().find(|(i, _)| *i == id) {
                            Some((_, count)) => *count += 1,
                            None => ids.push((id, 1)),
                        }
                    }
                }
                let centre = (
                    ((px0 + x) * ss) as f64 + ss as f64 * 0.5,
                    ((py0 + y) * ss) as f64 + ss as f64 * 0.5,
                );
                let mut sum = [0.0f32; 3];
                for &(id, count) in &ids {
                    let c = if id == EMPTY {
                        background
                    } else {
                        self.shade(id, centre)
                    };
                    for k in 0..3 {
                        sum[k] += c[k] * count as f32;
                    }
                }
                let o = ((y * w + x) * 4) as usize;
                for k in 0..3 {
                    out[o + k] = (sum[k] / n * 255.0).round().clamp(0.0, 255.0) as u8;
                }
                out[o + 3] = 255;
            }
        }
        out
    }
}

/// Renders `list` seen by `camera` into an RGBA8 image of `width × height` pixels, row-major.
pub fn render(list: &DrawList, camera: &Camera, options: &RenderOptions) -> Vec<u8> {
    let ss = options.supersample.max(1);
    let (w, h) = (options.width * ss, options.height * ss);
    let frame = Frame::new(camera, w, h);
    let per_pixel = ss as f64;
    let tris: Vec<TriSetup> = list
        .triangles
        .par_iter()
        .enumerate()
        .filter_map(|(i, t)| TriSetup::new(&frame, t, i as u32))
        .collect();
    let lines: Vec<LineSetup> = list
        .lines
        .par_iter()
        .filter_map(|l| LineSetup::new(&frame, l, per_pixel))
        .collect();
    let points: Vec<PointSetup> = list
        .points
        .par_iter()
        .filter_map(|p| PointSetup::new(&frame, p, per_pixel))
        .collect();
    let grid = Grid::new(w, h, TILE * ss);
    let tri_bins = Bins::new(&tris, |t| t.rect, &grid);
    let line_bins = Bins::new(&lines, |l| l.rect, &grid);
    let point_bins = Bins::new(&points, |p| p.rect, &grid);
    let prepared = Prepared {
        list,
        tris,
        lines,
        points,
        shading: Shading::new(camera),
        options,
        ss,
    };
    let (nt, nl) = (prepared.tris.len() as u32, prepared.lines.len() as u32);

    let tiles: Vec<Vec<u8>> = (0..grid.count())
        .into_par_iter()
        .map_init(
            || Samples::new(grid.side),
            |samples, t| {
                let (tx, ty) = (t as u32 % grid.across, t as u32 / grid.across);
                samples.reset(Rect {
                    x0: tx * grid.side,
                    y0: ty * grid.side,
                    x1: ((tx + 1) * grid.side).min(w),
                    y1: ((ty + 1) * grid.side).min(h),
                });
                for id in tri_bins.tile(t) {
                    samples.triangle(&prepared.tris[id as usize], id);
                }
                for id in line_bins.tile(t) {
                    samples.line(&prepared.lines[id as usize], nt + id);
                }
                for id in point_bins.tile(t) {
                    samples.point(&prepared.points[id as usize], nt + nl + id);
                }
                prepared.resolve(samples)
            },
        )
        .collect();

    let (width, tile) = (options.width as usize, TILE as usize);
    let mut out = vec![0u8; width * options.height as usize * 4];
    for (t, pixels) in tiles.iter().enumerate() {
        let (tx, ty) = (t % grid.across as usize, t / grid.across as usize);
        let tile_width = tile.min(width - tx * tile);
        for (r, row) in pixels.chunks(tile_width * 4).enumerate() {
            let start = ((ty * tile + r) * width + tx * tile) * 4;
            out[start..start + row.len()].copy_from_slice(row);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::draw_list::{Line, Point};
    use nalgebra::Vector3;

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
