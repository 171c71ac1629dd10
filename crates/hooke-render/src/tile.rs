//! One tile of samples: depth and the id of the nearest primitive per sample, filled by the
//! rasteriser and then resolved (shaded and averaged) into output pixels.
//!
//! Shading is deferred to the downsampling: each output pixel shades each distinct primitive
//! among its samples once, at the pixel centre, as multisampling does. A pixel inside one
//! surface costs one shade however many samples it has.

use crate::setup::{LineSetup, PointSetup, Rect, SUB, TriSetup, edge};

/// No primitive covers the sample.
pub(crate) const EMPTY: u32 = u32::MAX;

/// Lines sit on the surfaces they outline; this much NDC depth slack keeps them visible.
pub(crate) const LINE_DEPTH_BIAS: f64 = 2e-4;

/// The samples of one tile: `area` in the sample buffer's coordinates.
pub(crate) struct Samples {
    pub area: Rect,
    pub stride: usize,
    pub depth: Vec<f32>,
    pub id: Vec<u32>,
}

impl Samples {
    pub fn new(side: u32) -> Self {
        let n = (side * side) as usize;
        Self {
            area: Rect {
                x0: 0,
                y0: 0,
                x1: 0,
                y1: 0,
            },
            stride: side as usize,
            depth: vec![f32::INFINITY; n],
            id: vec![EMPTY; n],
        }
    }

    /// Clears the buffers for the tile covering `area` (at most `side` on each axis).
    pub fn reset(&mut self, area: Rect) {
        self.area = area;
        self.depth.fill(f32::INFINITY);
        self.id.fill(EMPTY);
    }

    /// The sample index of `(x, y)` in buffer coordinates.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        (y - self.area.y0) as usize * self.stride + (x - self.area.x0) as usize
    }

    #[inline]
    fn clip(&self, r: &Rect) -> Option<Rect> {
        let c = Rect {
            x0: r.x0.max(self.area.x0),
            y0: r.y0.max(self.area.y0),
            x1: r.x1.min(self.area.x1),
            y1: r.y1.min(self.area.y1),
        };
        (c.x0 < c.x1 && c.y0 < c.y1).then_some(c)
    }

    #[inline]
    fn write(&mut self, i: usize, z: f32, id: u32) {
        if z < self.depth[i] {
            self.depth[i] = z;
            self.id[i] = id;
        }
    }

    /// Scan-converts a triangle with integer edge functions stepped along each row.
    ///
    /// A sample on an edge shared by two triangles belongs to exactly one of them (a
    /// top-left style rule: edges pointing down, or left when horizontal, are inclusive),
    /// so meshes have neither cracks nor doubly drawn samples.
    pub fn triangle(&mut self, t: &TriSetup, id: u32) {
        let Some(r) = self.clip(&t.rect) else {
            return;
        };
        let [a, b, c] = t.corners();
        let bias = |p: [i64; 2], q: [i64; 2]| {
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            if dy > 0 || (dy == 0 && dx < 0) { 0 } else { -1 }
        };
        let edges = [(b, c), (c, a), (a, b)];
        let biases = edges.map(|(p, q)| bias(p, q));
        let steps = edges.map(|(p, q)| -(q[1] - p[1]) * SUB);
        let z = t.z.map(|z| z as f64);
        let inv_area = 1.0 / t.area as f64;
        for y in r.y0..r.y1 {
            let p = [r.x0 as i64 * SUB + SUB / 2, y as i64 * SUB + SUB / 2];
            let mut e = edges.map(|(a, b)| edge(a, b, p));
            let row = self.index(r.x0, y);
            for k in 0..(r.x1 - r.x0) as usize {
                if (e[0] + biases[0]) | (e[1] + biases[1]) | (e[2] + biases[2]) >= 0 {
                    let depth =
                        (e[0] as f64 * z[0] + e[1] as f64 * z[1] + e[2] as f64 * z[2]) * inv_area;
                    self.write(row + k, depth as f32, id);
                }
                for j in 0..3 {
                    e[j] += steps[j];
                }
            }
        }
    }

    /// Scan-converts a line as a capsule, depth interpolated along it.
    pub fn line(&mut self, l: &LineSetup, id: u32) {
        let Some(r) = self.clip(&l.rect) else {
            return;
        };
        let d = (l.b.0 - l.a.0, l.b.1 - l.a.1);
        let len2 = d.0 * d.0 + d.1 * d.1;
        let half2 = l.half * l.half;
        for y in r.y0..r.y1 {
            let py = y as f64 + 0.5;
            for x in r.x0..r.x1 {
                let px = x as f64 + 0.5;
                let u = if len2 > 0.0 {
                    (((px - l.a.0) * d.0 + (py - l.a.1) * d.1) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (qx, qy) = (l.a.0 + d.0 * u - px, l.a.1 + d.1 * u - py);
                if qx * qx + qy * qy <= half2 {
                    let z = l.za + (l.zb - l.za) * u - LINE_DEPTH_BIAS;
                    let i = self.index(x, y);
                    self.write(i, z as f32, id);
                }
            }
        }
    }

    /// Scan-converts a point as a disc in front of what it marks.
    pub fn point(&mut self, p: &PointSetup, id: u32) {
        let Some(r) = self.clip(&p.rect) else {
            return;
        };
        let r2 = p.radius * p.radius;
        let z = (p.z - 2.0 * LINE_DEPTH_BIAS) as f32;
        for y in r.y0..r.y1 {
            let dy = y as f64 + 0.5 - p.c.1;
            for x in r.x0..r.x1 {
                let dx = x as f64 + 0.5 - p.c.0;
                if dx * dx + dy * dy <= r2 {
                    let i = self.index(x, y);
                    self.write(i, z, id);
                }
            }
        }
    }
}
