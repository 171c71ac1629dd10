//! Primitive setup: world space to sample space, fixed-point triangle corners, and the
//! rectangle of sample centres each primitive may cover.

use crate::camera::Camera;
use crate::draw_list::{Line, Point, Rgb, Triangle};
use nalgebra::{Matrix4, Vector3, Vector4};

/// Sub-sample precision of triangle corners: 8 bits, 1/256 of a sample.
pub(crate) const SUB: i64 = 1 << 8;

/// Corners farther than this many samples from the origin are not drawn. It bounds every
/// fixed-point coordinate below 2^29, so edge functions (products of two differences) stay
/// below 2^61 and never overflow `i64`. Only triangles grazing the near plane reach it.
const GUARD: f64 = (1u32 << 21) as f64;

/// A half-open rectangle of sample indices `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Rect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

/// A point in sample space: x right, y down, in samples; `z` is NDC depth.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Projected {
    x: f64,
    y: f64,
    z: f64,
    inv_w: f64,
}

/// The projection of one frame into a `width × height` grid of samples.
pub(crate) struct Frame {
    m: Matrix4<f64>,
    near: f64,
    width: u32,
    height: u32,
}

impl Frame {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        Self {
            m: camera.view_projection(width as f64 / height as f64),
            near: camera.near(),
            width,
            height,
        }
    }

    /// `None` when the point is closer than the near plane (or behind the eye).
    pub fn project(&self, p: &Vector3<f64>) -> Option<Projected> {
        let c = self.m * Vector4::new(p.x, p.y, p.z, 1.0);
        if c.w.is_nan() || c.w < self.near {
            return None;
        }
        let inv_w = 1.0 / c.w;
        Some(Projected {
            x: (c.x * inv_w + 1.0) * 0.5 * self.width as f64,
            y: (1.0 - c.y * inv_w) * 0.5 * self.height as f64,
            z: c.z * inv_w,
            inv_w,
        })
    }

    /// The sample centres (at `i + 0.5`) within `[lo, hi]` on both axes, or `None`.
    fn rect(&self, lo: (f64, f64), hi: (f64, f64)) -> Option<Rect> {
        let first = |v: f64| (v - 0.5).ceil().max(0.0);
        let last = |v: f64, n: u32| (v - 0.5).floor().min(n as f64 - 1.0);
        let (x0, x1) = (first(lo.0), last(hi.0, self.width));
        let (y0, y1) = (first(lo.1), last(hi.1, self.height));
        (x0 <= x1 && y0 <= y1).then(|| Rect {
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1 as u32 + 1,
            y1: y1 as u32 + 1,
        })
    }
}

impl Frame {
    /// The sample centres within the fixed-point box `[min, max]`, in integer arithmetic.
    fn fixed_rect(&self, min: [i64; 2], max: [i64; 2]) -> Option<Rect> {
        // Sample i's centre is at i·SUB + SUB/2: the first at or after `lo`, the last at or
        // before `hi`.
        let first = |lo: i64| (lo - SUB / 2 + SUB - 1).div_euclid(SUB).max(0);
        let last = |hi: i64, n: u32| (hi - SUB / 2).div_euclid(SUB).min(n as i64 - 1);
        let (x0, x1) = (first(min[0]), last(max[0], self.width));
        let (y0, y1) = (first(min[1]), last(max[1], self.height));
        (x0 <= x1 && y0 <= y1).then(|| Rect {
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1 as u32 + 1,
            y1: y1 as u32 + 1,
        })
    }
}

/// A triangle ready to rasterise: corners in fixed point, ordered so that `area > 0`.
///
/// Set up once per triangle per frame and read by every tile it touches, so it is kept
/// small: corners as `i32` (the guard band bounds them by 2²⁹), widened for the edge
/// functions.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriSetup {
    /// Corners in 1/[`SUB`] samples.
    v: [[i32; 2]; 3],
    /// NDC depth at the corners.
    pub z: [f32; 3],
    /// `1/w` at the corners, for perspective-correct attributes.
    pub inv_w: [f32; 3],
    /// Twice the signed area in fixed units squared, positive.
    pub area: i64,
    /// Index among the frame's triangles: the meshes' in order, then the list's own.
    pub src: u32,
    /// Whether corners 1 and 2 were exchanged to make the area positive.
    pub swapped: bool,
    /// At most 2×2 samples across (a pixel or less at 4× AA): shaded with its mean corner
    /// normal, as interpolating inside it changes nothing visible.
    pub tiny: bool,
    pub rect: Rect,
    /// The mean corner normal and the colour, copied here because the downsampling needs them
    /// for every tiny triangle of a pixel: from the draw list that is a cache miss into
    /// hundreds of megabytes per triangle (measured: 14 % of a 2-million-triangle frame),
    /// from here a read of what the tile's scan conversion just touched.
    pub normal: Vector3<f64>,
}

/// The edge function of `a → b` at `p`: twice the signed area of `(a, b, p)`.
#[inline]
pub(crate) fn edge(a: [i64; 2], b: [i64; 2], p: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

impl TriSetup {
    pub fn new(frame: &Frame, t: &Triangle, src: u32) -> Option<Self> {
        let p = [
            frame.project(&t.p[0])?,
            frame.project(&t.p[1])?,
            frame.project(&t.p[2])?,
        ];
        Self::projected(frame, p, &t.n, src)
    }

    /// A triangle from its corners already projected (a mesh's, projected once per frame)
    /// and its corner normals `n`.
    #[inline]
    pub fn projected(
        frame: &Frame,
        p: [Projected; 3],
        n: &[Vector3<f64>; 3],
        src: u32,
    ) -> Option<Self> {
        if p.iter().any(|q| q.x.abs() > GUARD || q.y.abs() > GUARD) {
            return None;
        }
        // Round to nearest by truncating a positive number: the guard band keeps
        // `v·SUB + BIAS` positive, and `as` truncation avoids a libm call per coordinate.
        const BIAS: f64 = (1u64 << 40) as f64;
        let round = |v: f64| (v * SUB as f64 + (BIAS + 0.5)) as i64 - BIAS as i64;
        let fixed = |q: &Projected| [round(q.x), round(q.y)];
        let mut v = p.each_ref().map(fixed);
        let mut z = p.map(|q| q.z as f32);
        let mut inv_w = p.map(|q| q.inv_w as f32);
        let mut area = edge(v[0], v[1], v[2]);
        if area == 0 {
            return None;
        }
        let swapped = area < 0;
        if swapped {
            v.swap(1, 2);
            z.swap(1, 2);
            inv_w.swap(1, 2);
            area = -area;
        }
        // Written out: as iterator folds these were left uninlined, a fifth of set-up.
        let (min, max) = (
            [0, 1].map(|a| v[0][a].min(v[1][a]).min(v[2][a])),
            [0, 1].map(|a| v[0][a].max(v[1][a]).max(v[2][a])),
        );
        let rect = frame.fixed_rect(min, max)?;
        Some(Self {
            // In range: |x|, |y| <= GUARD samples, so |v| <= 2²⁹ + 1.
            v: v.map(|c| c.map(|x| x as i32)),
            z,
            inv_w,
            area,
            src,
            swapped,
            tiny: rect.x1 - rect.x0 <= 2 && rect.y1 - rect.y0 <= 2,
            rect,
            normal: (n[0] + n[1] + n[2]) * (1.0 / 3.0),
        })
    }

    /// The corners, widened for edge functions (whose products need 64 bits).
    #[inline]
    pub fn corners(&self) -> [[i64; 2]; 3] {
        self.v.map(|c| c.map(i64::from))
    }

    /// Perspective-correct barycentric weights of the draw list's corners at the sample-space
    /// point `p`, clamped to the triangle.
    pub fn weights(&self, p: (f64, f64)) -> [f64; 3] {
        let s = SUB as f64;
        let v = self.v.map(|c| (c[0] as f64 / s, c[1] as f64 / s));
        let e =
            |a: (f64, f64), b: (f64, f64)| (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0);
        let b = [e(v[1], v[2]), e(v[2], v[0]), e(v[0], v[1])];
        let mut w = [0.0; 3];
        for k in 0..3 {
            w[k] = b[k].max(0.0) * self.inv_w[k] as f64;
        }
        let sum = w[0] + w[1] + w[2];
        let w = if sum > 0.0 {
            let inv = 1.0 / sum;
            [w[0] * inv, w[1] * inv, w[2] * inv]
        } else {
            [1.0 / 3.0; 3]
        };
        if self.swapped { [w[0], w[2], w[1]] } else { w }
    }
}

/// A line as a capsule of radius `half` samples.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LineSetup {
    pub a: (f64, f64),
    pub b: (f64, f64),
    pub za: f64,
    pub zb: f64,
    pub half: f64,
    pub color: Rgb,
    pub rect: Rect,
}

impl LineSetup {
    pub fn new(frame: &Frame, l: &Line, samples_per_pixel: f64) -> Option<Self> {
        let (a, b) = (frame.project(&l.a)?, frame.project(&l.b)?);
        let half = (l.width as f64 * samples_per_pixel * 0.5).max(0.5);
        let rect = frame.rect(
            (a.x.min(b.x) - half, a.y.min(b.y) - half),
            (a.x.max(b.x) + half, a.y.max(b.y) + half),
        )?;
        Some(Self {
            a: (a.x, a.y),
            b: (b.x, b.y),
            za: a.z,
            zb: b.z,
            half,
            color: l.color,
            rect,
        })
    }
}

/// A point as a shaded disc of `radius` samples.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PointSetup {
    pub c: (f64, f64),
    pub z: f64,
    pub radius: f64,
    pub color: Rgb,
    pub rect: Rect,
}

impl PointSetup {
    pub fn new(frame: &Frame, p: &Point, samples_per_pixel: f64) -> Option<Self> {
        let c = frame.project(&p.p)?;
        let radius = (p.radius as f64 * samples_per_pixel).max(0.5);
        let rect = frame.rect((c.x - radius, c.y - radius), (c.x + radius, c.y + radius))?;
        Some(Self {
            c: (c.x, c.y),
            z: c.z,
            radius,
            color: p.color,
            rect,
        })
    }
}
