//! Shadows: a shadow map seen from the key light (Williams 1978), read with
//! percentage-closer filtering (Reeves, Salesin & Cook 1987) for soft edges.
//!
//! The key light is directional, so the map is an orthographic view along it: every
//! triangle of the frame is drawn into a square grid over the light-space bounds of the
//! whole draw list, keeping per texel the height towards the light of the nearest surface.
//! A shaded point is lit in proportion to the texels around its own that lie no nearer the
//! light than it does. Texels are filled in bands of rows, each by one thread over the
//! triangles that reach it in list order, taking the maximum: the same bits on any thread
//! count.

use crate::draw_list::DrawList;
use nalgebra::Vector3;
use rayon::prelude::*;

/// Texels along each side of the map.
pub(crate) const SIDE: usize = 1024;
/// Texels along each side of a block of the coarse map.
const BLOCK: usize = 4;
/// Blocks along each side of the coarse map.
const BLOCKS: usize = SIDE / BLOCK;
/// Rows of texels a thread fills at once.
const BAND: usize = 32;
/// How near, in texels along the light, a shadowing surface darkens the ambient light.
const CONTACT: f64 = 6.0;
/// Texels beyond the bias before a shadowing surface counts as near.
const GRAZE: f64 = 4.0;
/// Texels a looked-up point is lifted along its normal: a smooth-shaded surface's normal
/// differs from its flat triangles' in the map, most where the light grazes it.
const LIFT: f64 = 3.0;
/// The share of the ambient light a surface touching its shadower loses.
const CONTACT_DARKENING: f64 = 0.5;
/// The filter: 3×3 taps this many texels apart, over a 5×5-texel footprint.
const TAP: i64 = 2;

/// Depths of the frame's surfaces seen from the key light.
pub(crate) struct ShadowMap {
    /// Light-space axes: `u`, `v` across the map, `l` towards the light.
    u: Vector3<f64>,
    v: Vector3<f64>,
    l: Vector3<f64>,
    /// The map's corner in `(u, v)` and its texel size, metres.
    origin: (f64, f64),
    texel: f64,
    /// Per texel, the largest `l`-height of a surface over it (−∞: none).
    height: Vec<f32>,
    /// Per block of [`BLOCK`]² texels, the largest of their heights: a point that every
    /// block its filter reads lies above is lit, found in a few reads of a map that stays
    /// in cache instead of the filter's nine.
    blocks: Vec<f32>,
}

impl ShadowMap {
    /// The map of `list`'s triangles, lines and points under a light from direction `light`
    /// (unit, towards the light); `None` when the list has none. A line or point casts the
    /// shadow of a strip or square as wide as it is drawn, `metres_per_pixel` the width of
    /// a pixel at the camera's target (a chain's shadow is its links' width).
    pub(crate) fn new(list: &DrawList, light: Vector3<f64>, metres_per_pixel: f64) -> Option<Self> {
        let l = light.normalize();
        let helper = if l.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::z()
        };
        let u = l.cross(&helper).normalize();
        let v = l.cross(&u);
        let mut lo = (f64::INFINITY, f64::INFINITY);
        let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        let mut corners = 0usize;
        let mut take = |q: Vector3<f64>| {
            let (a, b) = (q.dot(&u), q.dot(&v));
            if a.is_finite() && b.is_finite() {
                lo = (lo.0.min(a), lo.1.min(b));
                hi = (hi.0.max(a), hi.1.max(b));
                corners += 1;
            }
        };
        for_each_triangle(list, |p| p.into_iter().for_each(&mut take));
        for line in &list.lines {
            take(line.a);
            take(line.b);
        }
        for point in &list.points {
            take(point.p);
        }
        if corners == 0 {
            return None;
        }
        let extent = (hi.0 - lo.0).max(hi.1 - lo.1).max(1e-6);
        // Half a texel of room on each side, so that no corner lies on the map's edge.
        let texel = extent / (SIDE as f64 - 1.0);
        let origin = (lo.0 - 0.5 * texel, lo.1 - 0.5 * texel);
        let mut map = Self {
            u,
            v,
            l,
            origin,
            texel,
            height: vec![f32::NEG_INFINITY; SIDE * SIDE],
            blocks: vec![f32::NEG_INFINITY; BLOCKS * BLOCKS],
        };
        // Each mesh corner is taken to light space once, however many triangles share it.
        let mut triangles: Vec<[(f64, f64, f64); 3]> = Vec::with_capacity(list.triangle_count());
        for mesh in &list.meshes {
            let corners: Vec<(f64, f64, f64)> = mesh
                .positions
                .par_iter()
                .map(|q| map.light_space(q))
                .collect();
            let corner = |c: u32| corners.get(c as usize).copied();
            triangles.par_extend(
                mesh.triangles
                    .par_iter()
                    .filter_map(|t| Some([corner(t[0])?, corner(t[1])?, corner(t[2])?])),
            );
        }
        triangles.extend(
            list.triangles
                .iter()
                .map(|t| t.p.map(|q| map.light_space(&q))),
        );
        // Lines and points as quads across the light: half their drawn width each side, and
        // at least half a texel, so that a thin chain still shades the texels it crosses.
        let half = |pixels: f32| (0.5 * f64::from(pixels) * metres_per_pixel / map.texel).max(0.5);
        for line in &list.lines {
            let (a, b) = (map.light_space(&line.a), map.light_space(&line.b));
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let len = (dx * dx + dy * dy).sqrt();
            let w = half(line.width);
            // Across the line in the map; a line along the light is a square.
            let (nx, ny) = if len > 1e-12 {
                (-dy / len * w, dx / len * w)
            } else {
                (w, 0.0)
            };
            let (ex, ey) = if len > 1e-12 { (0.0, 0.0) } else { (0.0, w) };
            let p = |c: (f64, f64, f64), sx: f64, sy: f64| (c.0 + sx, c.1 + sy, c.2);
            let corners = [
                p(a, nx - ex, ny - ey),
                p(b, nx + ex, ny + ey),
                p(b, -nx + ex, -ny + ey),
                p(a, -nx - ex, -ny - ey),
            ];
            triangles.push([corners[0], corners[1], corners[2]]);
            triangles.push([corners[0], corners[2], corners[3]]);
        }
        for point in &list.points {
            let c = map.light_space(&point.p);
            let r = half(2.0 * point.radius);
            let q = |sx: f64, sy: f64| (c.0 + sx * r, c.1 + sy * r, c.2);
            triangles.push([q(-1.0, -1.0), q(1.0, -1.0), q(1.0, 1.0)]);
            triangles.push([q(-1.0, -1.0), q(1.0, 1.0), q(-1.0, 1.0)]);
        }
        // Each band's triangles, in list order: a band reads only those that reach it.
        let mut bands: Vec<Vec<u32>> = vec![Vec::new(); SIDE.div_ceil(BAND)];
        for (k, t) in triangles.iter().enumerate() {
            let ys = t.map(|p| p.1);
            let (lo, hi) = (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]));
            if !(lo.is_finite() && hi.is_finite()) {
                continue;
            }
            let count = bands.len();
            let last = ((hi + 0.5).max(0.0) as usize / BAND).min(count - 1);
            let first = ((lo - 0.5).max(0.0) as usize / BAND).min(last);
            for band in &mut bands[first..=last] {
                band.push(k as u32);
            }
        }
        map.height
            .par_chunks_mut(BAND * SIDE)
            .zip(bands.par_iter())
            .enumerate()
            .for_each(|(band, (rows, ids))| fill(rows, band * BAND, &triangles, ids));
        let height = &map.height;
        map.blocks
            .par_chunks_mut(BLOCKS)
            .enumerate()
            .for_each(|(by, row)| {
                for (bx, block) in row.iter_mut().enumerate() {
                    for y in by * BLOCK..(by + 1) * BLOCK {
                        let texels = &height[y * SIDE + bx * BLOCK..][..BLOCK];
                        *block = texels.iter().fold(*block, |m, &h| m.max(h));
                    }
                }
            });
        Some(map)
    }

    /// `(column, row, height)` of world point `q` in texel units.
    fn light_space(&self, q: &Vector3<f64>) -> (f64, f64, f64) {
        (
            (q.dot(&self.u) - self.origin.0) / self.texel,
            (q.dot(&self.v) - self.origin.1) / self.texel,
            q.dot(&self.l),
        )
    }

    /// The share of the key light that reaches world point `q` on a surface of unit normal
    /// `n` (either side), 0 in full shadow, 1 in full light, between them at a shadow's
    /// edge; and the share of the ambient light it keeps: less where the surface that
    /// shadows it is within a few texels (a cloth lying on a table, a body on the ground),
    /// the darkening that shows contact.
    pub(crate) fn light(&self, q: &Vector3<f64>, n: &Vector3<f64>) -> (f32, f32) {
        // The normal on the light's side, and an offset along it and a bias that grow where
        // the light grazes the surface: a surface does not shadow itself.
        let n = if n.dot(&self.l) < 0.0 { -n } else { *n };
        let cos = n.dot(&self.l).clamp(0.05, 1.0);
        let lifted = q + n * (LIFT * self.texel);
        let (x, y, h) = self.light_space(&lifted);
        let bias = self.texel * (1.5 + 2.0 * (1.0 - cos * cos).sqrt() / cos).min(16.0);
        let (cx, cy) = (x.floor() as i64, y.floor() as i64);
        if self.clear_above((cx, cy), h, bias) {
            return (1.0, 1.0);
        }
        let (mut lit, mut all) = (0u32, 0u32);
        let reach = CONTACT * self.texel;
        // Each tap's nearness of what shadows it, averaged as the taps' light is: a fold of
        // cloth that shadows itself darkens smoothly, not in speckles.
        let mut near = 0.0;
        for dy in [-TAP, 0, TAP] {
            for dx in [-TAP, 0, TAP] {
                let (tx, ty) = (cx + dx, cy + dy);
                all += 1;
                let inside = (0..SIDE as i64).contains(&tx) && (0..SIDE as i64).contains(&ty);
                let above = if inside {
                    self.height[ty as usize * SIDE + tx as usize] as f64 - h
                } else {
                    f64::NEG_INFINITY
                };
                if above <= bias {
                    lit += 1;
                } else if above > bias + GRAZE * self.texel {
                    // Past the bias by a margin: a curved surface's own texels, which lie
                    // just past the bias where the light grazes it, would speckle it.
                    near += (-(above - bias - GRAZE * self.texel) / reach).exp();
                }
            }
        }
        let ambient = 1.0 - CONTACT_DARKENING * near / all as f64;
        (lit as f32 / all as f32, ambient as f32)
    }
}

impl ShadowMap {
    /// Whether every texel the filter reads around `(cx, cy)` lies no more than `bias`
    /// above height `h` (those off the map count as clear), from the coarse map: computed
    /// as the filter computes it (`height − h ≤ bias`, which rounding keeps monotone in
    /// the height), so that a clear point gets exactly the filter's answer.
    fn clear_above(&self, (cx, cy): (i64, i64), h: f64, bias: f64) -> bool {
        let last = SIDE as i64 - 1;
        let (x0, x1) = ((cx - TAP).max(0), (cx + TAP).min(last));
        let (y0, y1) = ((cy - TAP).max(0), (cy + TAP).min(last));
        if x0 > x1 || y0 > y1 {
            return true;
        }
        let b = BLOCK as i64;
        for by in y0 / b..=y1 / b {
            for bx in x0 / b..=x1 / b {
                if self.blocks[by as usize * BLOCKS + bx as usize] as f64 - h > bias {
                    return false;
                }
            }
        }
        true
    }
}

/// Every triangle of `list` (the meshes', then the list's own) as its three corners.
fn for_each_triangle(list: &DrawList, mut f: impl FnMut([Vector3<f64>; 3])) {
    for mesh in &list.meshes {
        for t in &mesh.triangles {
            let corner = |c: u32| mesh.positions.get(c as usize).copied();
            if let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) {
                f([a, b, c]);
            }
        }
    }
    for t in &list.triangles {
        f(t.p);
    }
}

/// Draws the `triangles` (in texel units) named by `ids` into `rows`, the map's rows from
/// `first` on, keeping per texel the greatest height at its centre.
fn fill(rows: &mut [f32], first: usize, triangles: &[[(f64, f64, f64); 3]], ids: &[u32]) {
    let count = rows.len() / SIDE;
    let (y0, y1) = (first as f64, (first + count) as f64);
    for t in ids.iter().map(|&k| &triangles[k as usize]) {
        let ys = t.map(|p| p.1);
        let (lo, hi) = (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]));
        if hi < y0 - 0.5 || lo > y1 + 0.5 || !(lo.is_finite() && hi.is_finite()) {
            continue;
        }
        let [a, b, c] = *t;
        let area = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
        if area.abs() < 1e-12 {
            continue;
        }
        let xs = t.map(|p| p.0);
        let x_lo = (xs[0].min(xs[1]).min(xs[2]) - 0.5).ceil().max(0.0) as usize;
        let x_hi = ((xs[0].max(xs[1]).max(xs[2]) - 0.5).floor()).min(SIDE as f64 - 1.0);
        let r_lo = ((lo - 0.5).ceil().max(y0)) as usize;
        let r_hi = ((hi - 0.5).floor()).min(y1 - 1.0);
        if x_hi < 0.0 || r_hi < r_lo as f64 {
            continue;
        }
        let (x_hi, r_hi) = (x_hi as usize, r_hi as usize);
        let inv = 1.0 / area;
        for r in r_lo..=r_hi {
            let py = r as f64 + 0.5;
            let row = &mut rows[(r - first) * SIDE..][..SIDE];
            for (col, texel) in row.iter_mut().enumerate().take(x_hi + 1).skip(x_lo) {
                let px = col as f64 + 0.5;
                let w0 = ((b.0 - px) * (c.1 - py) - (b.1 - py) * (c.0 - px)) * inv;
                let w1 = ((c.0 - px) * (a.1 - py) - (c.1 - py) * (a.0 - px)) * inv;
                let w2 = 1.0 - w0 - w1;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let h = (w0 * a.2 + w1 * b.2 + w2 * c.2) as f32;
                if h > *texel {
                    *texel = h;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square metre at height `y`, and a big ground square at 0.
    fn slab(y: f64) -> DrawList {
        let mut list = DrawList::default();
        let quad = |list: &mut DrawList, half: f64, y: f64| {
            let p = |x: f64, z: f64| Vector3::new(x, y, z);
            list.flat([p(-half, -half), p(half, -half), p(half, half)], [0.5; 3]);
            list.flat([p(-half, -half), p(half, half), p(-half, half)], [0.5; 3]);
        };
        quad(&mut list, 2.0, 0.0);
        quad(&mut list, 0.5, y);
        list
    }

    #[test]
    fn ground_under_a_slab_is_shadowed_and_darker_where_the_slab_is_near() {
        let up = Vector3::y();
        let below = |y: f64| {
            let map = ShadowMap::new(&slab(y), up, 0.01).unwrap();
            map.light(&Vector3::zeros(), &up)
        };
        let (near, far) = (below(0.04), below(1.0));
        assert_eq!((near.0, far.0), (0.0, 0.0), "both in full shadow");
        assert!(near.1 < 0.75, "ambient kept 4 cm under: {}", near.1);
        assert!(far.1 > 0.99, "ambient kept 1 m under: {}", far.1);
        // Beside the slab, in the light.
        let map = ShadowMap::new(&slab(0.01), up, 0.01).unwrap();
        assert_eq!(map.light(&Vector3::new(1.5, 0.0, 0.0), &up), (1.0, 1.0));
    }

    /// A chain drawn as lines 4 pixels wide (4 cm at 1 cm a pixel), 0.5 m over the ground,
    /// shadows the ground under it and not 10 cm beside it.
    #[test]
    fn a_line_casts_a_shadow_as_wide_as_it_is_drawn() {
        let up = Vector3::y();
        let mut list = slab(-1.0);
        list.lines.push(crate::draw_list::Line {
            a: Vector3::new(-0.5, 0.5, 0.0),
            b: Vector3::new(0.5, 0.5, 0.0),
            color: [0.5; 3],
            width: 4.0,
        });
        let map = ShadowMap::new(&list, up, 0.01).unwrap();
        assert_eq!(map.light(&Vector3::new(0.2, 0.0, 0.0), &up).0, 0.0);
        assert_eq!(map.light(&Vector3::new(0.2, 0.0, 0.1), &up).0, 1.0);
    }
}
