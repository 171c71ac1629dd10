//! The rasterizer: z-buffered triangles, lines and points into a supersampled buffer, rows
//! split into bands with one writer each, then averaged down.
//!
//! Each band walks every primitive in list order, so the picture is the same bits whatever
//! the number of threads. Attributes are interpolated perspective-correctly: barycentrics are
//! weighted by `1/w` and renormalised (the derivation is in Low, "Perspective-Correct
//! Interpolation", 2002).

use crate::camera::Camera;
use crate::draw_list::{DrawList, Rgb};
use nalgebra::{Vector3, Vector4};
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

/// Rows per band: small enough to share work between two cores evenly, large enough that
/// walking the primitive list per band costs little.
const BAND: usize = 16;

#[derive(Clone, Copy)]
struct Projected {
    x: f64,
    y: f64,
    z: f64,
    inv_w: f64,
}

fn project(
    m: &nalgebra::Matrix4<f64>,
    p: &Vector3<f64>,
    near: f64,
    w: f64,
    h: f64,
) -> Option<Projected> {
    let c = m * Vector4::new(p.x, p.y, p.z, 1.0);
    if c.w < near {
        return None;
    }
    let inv_w = 1.0 / c.w;
    Some(Projected {
        x: (c.x * inv_w + 1.0) * 0.5 * w,
        y: (1.0 - c.y * inv_w) * 0.5 * h,
        z: c.z * inv_w,
        inv_w,
    })
}

struct Target<'a> {
    color: &'a mut [Rgb],
    depth: &'a mut [f64],
    y0: usize,
    rows: usize,
    width: usize,
}

impl Target<'_> {
    #[inline]
    fn test_and_set(&mut self, x: usize, y: usize, z: f64) -> Option<usize> {
        let i = (y - self.y0) * self.width + x;
        (z < self.depth[i]).then(|| {
            self.depth[i] = z;
            i
        })
    }
}

/// Lighting: a key light from the upper front-left in view terms, plus ambient and a little
/// specular; surfaces are two-sided.
struct Shading {
    light: Vector3<f64>,
    half: Vector3<f64>,
    forward: Vector3<f64>,
}

impl Shading {
    fn new(camera: &Camera) -> Self {
        let forward = (camera.target - camera.eye()).normalize();
        let right = forward.cross(&Vector3::y()).normalize();
        let light = (Vector3::y() * 1.2 - right * 0.5 - forward * 0.6).normalize();
        let half = (light - forward).normalize();
        Self {
            light,
            half,
            forward,
        }
    }

    fn shade(&self, n: Vector3<f64>, color: Rgb) -> Rgb {
        let n = if n.dot(&self.forward) > 0.0 { -n } else { n };
        let diffuse = n.dot(&self.light).max(0.0);
        let specular = n.dot(&self.half).max(0.0).powi(32) * 0.25;
        color.map(|c| (c as f64 * (0.35 + 0.65 * diffuse) + specular).min(1.0) as f32)
    }
}

/// Renders `list` seen by `camera` into an RGBA8 image of `width × height` pixels, row-major.
pub fn render(list: &DrawList, camera: &Camera, options: &RenderOptions) -> Vec<u8> {
    let ss = options.supersample.max(1) as usize;
    let (w, h) = (options.width as usize * ss, options.height as usize * ss);
    let m = camera.view_projection(w as f64 / h as f64);
    let near = camera.near();
    let (wf, hf) = (w as f64, h as f64);
    let tris: Vec<Option<[Projected; 3]>> = list
        .triangles
        .par_iter()
        .map(|t| {
            Some([
                project(&m, &t.p[0], near, wf, hf)?,
                project(&m, &t.p[1], near, wf, hf)?,
                project(&m, &t.p[2], near, wf, hf)?,
            ])
        })
        .collect();
    let lines: Vec<Option<[Projected; 2]>> = list
        .lines
        .iter()
        .map(|l| {
            Some([
                project(&m, &l.a, near, wf, hf)?,
                project(&m, &l.b, near, wf, hf)?,
            ])
        })
        .collect();
    let points: Vec<Option<Projected>> = list
        .points
        .iter()
        .map(|p| project(&m, &p.p, near, wf, hf))
        .collect();
    let shading = Shading::new(camera);

    let mut color = vec![[0.0f32; 3]; w * h];
    let mut depth = vec![f64::INFINITY; w * h];
    color
        .par_chunks_mut(BAND * w)
        .zip(depth.par_chunks_mut(BAND * w))
        .enumerate()
        .for_each(|(band, (color, depth))| {
            let y0 = band * BAND;
            let rows = color.len() / w;
            for (r, row) in color.chunks_mut(w).enumerate() {
                let t = (y0 + r) as f32 / h as f32;
                let [top, bottom] = options.background;
                row.fill([0, 1, 2].map(|c| top[c] * (1.0 - t) + bottom[c] * t));
            }
            let mut target = Target {
                color,
                depth,
                y0,
                rows,
                width: w,
            };
            for (t, s) in list.triangles.iter().zip(&tris) {
                if let Some(s) = s {
                    triangle(&mut target, s, |b| {
                        let n = t.n[0] * b[0] + t.n[1] * b[1] + t.n[2] * b[2];
                        shading.shade(n.try_normalize(1e-12).unwrap_or(t.n[0]), t.color)
                    });
                }
            }
            for (l, s) in list.lines.iter().zip(&lines) {
                if let Some([a, b]) = s {
                    line(&mut target, a, b, l.width as f64 * ss as f64, l.color);
                }
            }
            for (p, s) in list.points.iter().zip(&points) {
                if let Some(c) = s {
                    ball(
                        &mut target,
                        c,
                        p.radius as f64 * ss as f64,
                        p.color,
                        &shading,
                    );
                }
            }
        });
    downsample(&color, options.width as usize, options.height as usize, ss)
}

fn edge(a: (f64, f64), b: (f64, f64), p: (f64, f64)) -> f64 {
    (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0)
}

fn triangle(t: &mut Target, s: &[Projected; 3], shade: impl Fn([f64; 3]) -> Rgb) {
    let pts = s.map(|p| (p.x, p.y));
    let area = edge(pts[0], pts[1], pts[2]);
    if area.abs() < 1e-12 {
        return;
    }
    let (y_lo, y_hi) = (t.y0 as f64, (t.y0 + t.rows) as f64);
    let min_x = pts
        .iter()
        .map(|p| p.0)
        .fold(f64::INFINITY, f64::min)
        .floor()
        .max(0.0) as usize;
    let max_x = (pts
        .iter()
        .map(|p| p.0)
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil()
        .min(t.width as f64))
    .max(0.0) as usize;
    let min_y = pts
        .iter()
        .map(|p| p.1)
        .fold(f64::INFINITY, f64::min)
        .floor()
        .max(y_lo) as usize;
    let max_y = (pts
        .iter()
        .map(|p| p.1)
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil()
        .min(y_hi))
    .max(y_lo) as usize;
    for y in min_y..max_y {
        for x in min_x..max_x {
            let p = (x as f64 + 0.5, y as f64 + 0.5);
            let b = [
                edge(pts[1], pts[2], p) / area,
                edge(pts[2], pts[0], p) / area,
                edge(pts[0], pts[1], p) / area,
            ];
            if b.iter().any(|&v| v < 0.0) {
                continue;
            }
            let z = b[0] * s[0].z + b[1] * s[1].z + b[2] * s[2].z;
            if let Some(i) = t.test_and_set(x, y, z) {
                let pc = [b[0] * s[0].inv_w, b[1] * s[1].inv_w, b[2] * s[2].inv_w];
                let sum = pc[0] + pc[1] + pc[2];
                t.color[i] = shade(pc.map(|v| v / sum));
            }
        }
    }
}

/// Lines sit on surfaces they outline; this much depth slack keeps them visible there.
const LINE_DEPTH_BIAS: f64 = 2e-4;

fn line(t: &mut Target, a: &Projected, b: &Projected, width: f64, color: Rgb) {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let steps = (dx.abs().max(dy.abs()) * 2.0).ceil().max(1.0) as usize;
    let half = (width * 0.5).max(0.5);
    for k in 0..=steps {
        let u = k as f64 / steps as f64;
        let (cx, cy, z) = (
            a.x + dx * u,
            a.y + dy * u,
            a.z + (b.z - a.z) * u - LINE_DEPTH_BIAS,
        );
        let y_lo = ((cy - half).floor().max(t.y0 as f64)) as usize;
        let y_hi = ((cy + half).ceil().min((t.y0 + t.rows) as f64)).max(y_lo as f64) as usize;
        let x_lo = (cx - half).floor().max(0.0) as usize;
        let x_hi = ((cx + half).ceil().min(t.width as f64)).max(x_lo as f64) as usize;
        for y in y_lo..y_hi {
            for x in x_lo..x_hi {
                if let Some(i) = t.test_and_set(x, y, z) {
                    t.color[i] = color;
                }
            }
        }
    }
}

fn ball(t: &mut Target, c: &Projected, radius: f64, color: Rgb, shading: &Shading) {
    let y_lo = ((c.y - radius).floor().max(t.y0 as f64)) as usize;
    let y_hi = ((c.y + radius).ceil().min((t.y0 + t.rows) as f64)).max(y_lo as f64) as usize;
    let x_lo = (c.x - radius).floor().max(0.0) as usize;
    let x_hi = ((c.x + radius).ceil().min(t.width as f64)).max(x_lo as f64) as usize;
    let right = shading.forward.cross(&Vector3::y()).normalize();
    let up = right.cross(&shading.forward);
    for y in y_lo..y_hi {
        for x in x_lo..x_hi {
            let (u, v) = (
                (x as f64 + 0.5 - c.x) / radius,
                (c.y - y as f64 - 0.5) / radius,
            );
            let r2 = u * u + v * v;
            if r2 > 1.0 {
                continue;
            }
            let n = right * u + up * v - shading.forward * (1.0 - r2).sqrt();
            if let Some(i) = t.test_and_set(x, y, c.z - LINE_DEPTH_BIAS * 2.0) {
                t.color[i] = shading.shade(n, color);
            }
        }
    }
}

fn downsample(color: &[Rgb], width: usize, height: usize, ss: usize) -> Vec<u8> {
    let mut out = vec![0u8; width * height * 4];
    out.par_chunks_mut(width * 4)
        .enumerate()
        .for_each(|(y, row)| {
            for x in 0..width {
                let mut sum = [0.0f32; 3];
                for sy in 0..ss {
                    for sx in 0..ss {
                        let c = color[(y * ss + sy) * width * ss + x * ss + sx];
                        for k in 0..3 {
                            sum[k] += c[k];
                        }
                    }
                }
                let n = (ss * ss) as f32;
                for k in 0..3 {
                    row[x * 4 + k] = (sum[k] / n * 255.0).round().clamp(0.0, 255.0) as u8;
                }
                row[x * 4 + 3] = 255;
            }
        });
    out
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
