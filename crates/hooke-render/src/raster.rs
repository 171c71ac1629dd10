//! The rasterizer: tiles of samples kept in cache, each filled with every primitive that
//! touches it and resolved straight into output pixels, so no full-size supersampled frame
//! is ever allocated.
//!
//! The pipeline: primitive setup in parallel over the draw list (projection, fixed-point
//! corners, sample rectangles); binning into tiles in fixed chunks; then in parallel over
//! tiles, scan conversion into a depth + primitive-id buffer and a downsampling that shades each
//! distinct primitive of a pixel once. Every tile sees its primitives in draw-list order and
//! no two tiles share a pixel, so the picture is the same bits whatever the thread count.
//! Attributes are interpolated perspective-correctly: barycentrics are weighted by `1/w`
//! and renormalised (Low, "Perspective-Correct Interpolation", 2002).

use crate::bins::{Bins, Grid};
use crate::camera::Camera;
use crate::downsample::Downsampler;
use crate::draw_list::DrawList;
use crate::options::RenderOptions;
use crate::setup::{Frame, LineSetup, PointSetup, Projected, Rect, TriSetup};
use crate::shading::Shading;
use crate::shadow::ShadowMap;
use crate::tile::Samples;
use rayon::prelude::*;

/// Tile side in output pixels: with 4× supersampling a tile's depth and id buffers take
/// 128 KiB, which stays in a core's L2 cache.
pub const TILE: u32 = 64;

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
    /// The sample rectangles of the set-up triangles, lines and points (`None` where
    /// culled), in draw-list order.
    rects: [Vec<Option<Rect>>; 3],
    /// Each tile's resolved pixels.
    tiles: Vec<Vec<u8>>,
    /// The current mesh's corners in sample space (`None` behind the near plane).
    projected: Vec<Option<Projected>>,
    /// The first triangle of each mesh, then the end of the last: meshes' triangles come
    /// first in `tris`, the list's own after them.
    mesh_start: Vec<usize>,
}

/// Sets up every primitive of `list` into `out` (of the same length), and each one's
/// sample rectangle into `rects` for the binning, which then streams 20 bytes per
/// primitive instead of reading each set-up record twice.
fn set_up<P: Sync, S: Send>(
    (out, rects): (&mut [Option<S>], &mut [Option<Rect>]),
    list: &[P],
    f: impl Fn(usize, &P) -> Option<S> + Sync,
    rect: impl Fn(&S) -> Rect + Sync,
) {
    out.par_iter_mut()
        .zip(rects.par_iter_mut())
        .zip(list.par_iter())
        .enumerate()
        .for_each(|(i, ((slot, r), p))| {
            *slot = f(i, p);
            *r = slot.as_ref().map(&rect);
        });
}

/// `out` and `rects` resized to `len` (reusing their memory), as slices for [`set_up`].
fn sized<'a, S>(
    out: &'a mut Vec<Option<S>>,
    rects: &'a mut Vec<Option<Rect>>,
    len: usize,
) -> (&'a mut [Option<S>], &'a mut [Option<Rect>]) {
    out.resize_with(len, || None);
    rects.resize(len, None);
    (out, rects)
}

impl Renderer {
    /// Renders `list` seen by `camera` into an RGBA8 image of `width × height` pixels,
    /// row-major. The pixels depend only on the arguments, never on earlier frames.
    pub fn render(&mut self, list: &DrawList, camera: &Camera, options: &RenderOptions) -> Vec<u8> {
        let supersample = options.supersample.max(1);
        let (w, h) = (options.width * supersample, options.height * supersample);
        let frame = Frame::new(camera, w, h);
        let per_pixel = supersample as f64;
        let [tri_rects, line_rects, point_rects] = &mut self.rects;
        let (mut tris, mut rects) = sized(&mut self.tris, tri_rects, list.triangle_count());
        self.mesh_start.clear();
        self.mesh_start.push(0);
        for mesh in &list.meshes {
            // Each corner once, however many triangles share it.
            mesh.positions
                .par_iter()
                .map(|p| frame.project(p))
                .collect_into_vec(&mut self.projected);
            let (start, projected) = (self.mesh_start[self.mesh_start.len() - 1], &self.projected);
            let corner = |c: u32| *projected.get(c as usize)?;
            let normal = |c: u32| mesh.normals.get(c as usize).copied();
            let (head, rest) = tris.split_at_mut(mesh.triangles.len());
            let (head_rects, rest_rects) = rects.split_at_mut(mesh.triangles.len());
            set_up(
                (head, head_rects),
                &mesh.triangles,
                |k, &[a, b, c]| {
                    let p = [corner(a)?, corner(b)?, corner(c)?];
                    let n = [normal(a)?, normal(b)?, normal(c)?];
                    TriSetup::projected(&frame, p, &n, (start + k) as u32)
                },
                |t| t.rect,
            );
            (tris, rects) = (rest, rest_rects);
            self.mesh_start.push(start + mesh.triangles.len());
        }
        let meshes_end = self.mesh_start[self.mesh_start.len() - 1];
        set_up(
            (tris, rects),
            &list.triangles,
            |i, t| TriSetup::new(&frame, t, (meshes_end + i) as u32),
            |t| t.rect,
        );
        set_up(
            sized(&mut self.lines, line_rects, list.lines.len()),
            &list.lines,
            |_, l| LineSetup::new(&frame, l, per_pixel),
            |l| l.rect,
        );
        set_up(
            sized(&mut self.points, point_rects, list.points.len()),
            &list.points,
            |_, p| PointSetup::new(&frame, p, per_pixel),
            |p| p.rect,
        );
        let grid = Grid::new(w, h, TILE * supersample);
        self.tri_bins.fill(&self.rects[0], &grid);
        self.line_bins.fill(&self.rects[1], &grid);
        self.point_bins.fill(&self.rects[2], &grid);
        let downsampler = Downsampler {
            list,
            mesh_start: &self.mesh_start,
            tris: &self.tris,
            lines: &self.lines,
            points: &self.points,
            shading: Shading::new(camera, options.ambient),
            shadow: if options.shadows {
                ShadowMap::new(
                    list,
                    camera.key_light(),
                    metres_per_pixel(camera, options.height),
                )
            } else {
                None
            },
            options,
            supersample,
        };
        // Sample ids: triangles, then lines, then points.
        let (line_ids, point_ids) = (
            self.tris.len() as u32,
            (self.tris.len() + self.lines.len()) as u32,
        );
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
                    downsampler.background_tile(&area, pixels);
                    return;
                }
                samples.reset(area);
                // Binned primitives are the set-up ones: the `if let` never skips.
                for id in tri_bins.tile(t) {
                    if let Some(s) = &downsampler.tris[id as usize] {
                        samples.triangle(s, id);
                    }
                }
                for id in line_bins.tile(t) {
                    if let Some(s) = &downsampler.lines[id as usize] {
                        samples.line(s, line_ids + id);
                    }
                }
                for id in point_bins.tile(t) {
                    if let Some(s) = &downsampler.points[id as usize] {
                        samples.point(s, point_ids + id);
                    }
                }
                downsampler.downsample(samples, pixels);
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

/// The width of an output pixel at the camera's target, metres: what a line or point drawn
/// so many pixels wide spans there (its shadow's width).
fn metres_per_pixel(camera: &Camera, height: u32) -> f64 {
    2.0 * camera.distance * (0.5 * camera.fov_y.to_radians()).tan() / f64::from(height.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::draw_list::{Line, Mesh, Point};
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

    /// A wavy, smooth-shaded 40 × 40 sheet in a blue no other test primitive has.
    fn wavy_sheet() -> Mesh {
        let (rows, cols) = (40, 40);
        let at = |r: usize, c: usize| {
            let (u, v) = (r as f64 / 39.0, c as f64 / 39.0);
            Vector3::new(
                u * 2.0 - 1.0,
                0.3 * (5.0 * u).sin() * (3.0 * v).cos(),
                v * 2.0 - 1.0,
            )
        };
        let positions: Vec<_> = (0..rows * cols).map(|k| at(k / cols, k % cols)).collect();
        let normals: Vec<_> = positions
            .iter()
            .map(|p| Vector3::new(p.y, 1.0, p.x).normalize())
            .collect();
        let mut triangles = Vec::new();
        for r in 0..rows - 1 {
            for c in 0..cols - 1 {
                let k = |r: usize, c: usize| (r * cols + c) as u32;
                triangles.push([k(r, c), k(r + 1, c), k(r + 1, c + 1)]);
                triangles.push([k(r, c), k(r + 1, c + 1), k(r, c + 1)]);
            }
        }
        Mesh {
            positions,
            normals,
            triangles,
            color: [0.05, 0.05, 0.9],
            colors: Vec::new(),
        }
    }

    #[test]
    fn pixels_do_not_depend_on_the_thread_count() {
        let mut list = scene();
        list.meshes.push(wavy_sheet());
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
    fn a_mesh_draws_the_pixels_of_its_triangles() {
        // A wavy sheet as a mesh and as free-standing triangles.
        let mesh = wavy_sheet();
        let mut as_mesh = scene();
        as_mesh.meshes.push(mesh.clone());
        let mut as_triangles = scene();
        let expanded: Vec<_> = (0..mesh.triangles.len())
            .map(|k| mesh.triangle(k).unwrap())
            .collect();
        // Meshes come first in the draw order: so do the expanded triangles.
        as_triangles.triangles.splice(0..0, expanded);
        let camera = Camera::framing(
            Vector3::new(-1.0, -0.5, -1.0),
            Vector3::new(1.0, 3.0, 1.0),
            30.0,
            35.0,
        );
        let options = RenderOptions {
            width: 200,
            height: 150,
            ..RenderOptions::default()
        };
        let mut renderer = Renderer::default();
        let pixels = renderer.render(&as_mesh, &camera, &options);
        assert_eq!(pixels, render(&as_triangles, &camera, &options));
        // The sheet shows: hundreds of pixels are its blue, found nowhere without it.
        let blue = |pixels: &[u8]| {
            let [r, g, b] = [0, 1, 2];
            pixels
                .chunks(4)
                .filter(|p| {
                    let c = |k: usize| i32::from(p[k]);
                    c(b) > c(r) + 100 && c(b) > c(g) + 100
                })
                .count()
        };
        assert!(blue(&pixels) > 500, "{}", blue(&pixels));
        assert_eq!(blue(&render(&scene(), &camera, &options)), 0);

        // A triangle naming a corner that does not exist is skipped, the rest drawn.
        as_mesh.meshes[0].triangles.push([0, 1, 99_999]);
        assert_eq!(as_mesh.triangle_count(), as_triangles.triangles.len() + 1);
        assert_eq!(as_mesh.meshes[0].triangle(mesh.triangles.len()), None);
        let with_bad = renderer.render(&as_mesh, &camera, &options);
        assert_eq!(with_bad, pixels);
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
