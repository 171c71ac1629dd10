//! What the drape meter reads off a draped specimen: the area it covers seen from above, and
//! its outline's radius against angle, whose peaks are its nodes.

use hooke_core::Vec3;

/// A draped specimen seen from above, on a raster of square cells `cell` metres wide
/// centred on the pedestal's axis (`x = z = 0`).
pub struct Shadow {
    /// Cells per side.
    pub side: usize,
    /// A cell's width, metres.
    pub cell: f64,
    /// Whether each cell's centre is covered, row by row (x fastest).
    pub covered: Vec<bool>,
}

impl Shadow {
    /// The shadow of `triangles` (indices into `x`) on a raster `cell` wide reaching
    /// `half` metres from the axis each way.
    pub fn of(x: &[Vec3], triangles: &[[u32; 3]], half: f64, cell: f64) -> Self {
        let side = (2.0 * half / cell).ceil() as usize;
        let mut covered = vec![false; side * side];
        let at = |k: usize| -half + (k as f64 + 0.5) * cell;
        let index = |c: f64| ((c + half) / cell - 0.5).clamp(0.0, (side - 1) as f64);
        for t in triangles {
            let [a, b, c] = t.map(|i| x[i as usize]);
            let edge = |p: (f64, f64), q: &Vec3, r: &Vec3| {
                (r.x - q.x) * (p.1 - q.z) - (r.z - q.z) * (p.0 - q.x)
            };
            let (lo, hi) = (a.inf(&b).inf(&c), a.sup(&b).sup(&c));
            let (i0, i1) = (index(lo.x).ceil() as usize, index(hi.x).floor() as usize);
            let (j0, j1) = (index(lo.z).ceil() as usize, index(hi.z).floor() as usize);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let p = (at(i), at(j));
                    let (d1, d2, d3) = (edge(p, &a, &b), edge(p, &b, &c), edge(p, &c, &a));
                    if (d1 >= 0.0 && d2 >= 0.0 && d3 >= 0.0)
                        || (d1 <= 0.0 && d2 <= 0.0 && d3 <= 0.0)
                    {
                        covered[j * side + i] = true;
                    }
                }
            }
        }
        Self {
            side,
            cell,
            covered,
        }
    }

    /// The covered area, m².
    pub fn area(&self) -> f64 {
        self.covered.iter().filter(|c| **c).count() as f64 * self.cell * self.cell
    }

    /// The outline's radius in each of `bins` equal sectors round the axis (sector 0 starts
    /// at +x, turning toward +z): the farthest covered cell centre in it, metres.
    pub fn outline(&self, bins: usize) -> Vec<f64> {
        let mut out = vec![0.0f64; bins];
        let half = 0.5 * self.side as f64 * self.cell;
        for j in 0..self.side {
            for i in 0..self.side {
                if !self.covered[j * self.side + i] {
                    continue;
                }
                let (x, z) = (
                    -half + (i as f64 + 0.5) * self.cell,
                    -half + (j as f64 + 0.5) * self.cell,
                );
                let angle = z.atan2(x).rem_euclid(std::f64::consts::TAU);
                let bin = ((angle / std::f64::consts::TAU * bins as f64) as usize).min(bins - 1);
                out[bin] = out[bin].max(x.hypot(z));
            }
        }
        out
    }
}

/// The nodes of a drape: peaks of the outline's radius `r` against angle (round the circle)
/// that rise at least `prominence` metres above the deeper of the two valleys between them
/// and the nearest higher peak on either side (topographic prominence).
pub fn nodes(r: &[f64], prominence: f64) -> usize {
    let n = r.len();
    if n < 3 {
        return 0;
    }
    // Smooth over three sectors: a single sector's raster step is no fold.
    let s: Vec<f64> = (0..n)
        .map(|k| (r[(k + n - 1) % n] + 2.0 * r[k] + r[(k + 1) % n]) / 4.0)
        .collect();
    let mut count = 0;
    for k in 0..n {
        let (prev, next) = (s[(k + n - 1) % n], s[(k + 1) % n]);
        // A plateau counts once, at its first sector.
        if !(s[k] > prev && s[k] >= next) {
            continue;
        }
        let walk = |step: isize| {
            let mut lowest = s[k];
            for m in 1..n {
                let j = (k as isize + step * m as isize).rem_euclid(n as isize) as usize;
                if s[j] > s[k] {
                    return lowest;
                }
                lowest = lowest.min(s[j]);
            }
            lowest
        };
        let base = walk(-1).max(walk(1));
        if s[k] - base >= prominence {
            count += 1;
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat disc's shadow is its area within 0.002 of the ring DC is a share of; an outline of `k` lobes has
    /// `k` nodes, and ripples below the prominence are none.
    #[test]
    fn a_disc_covers_its_area_and_lobes_count_as_nodes() {
        let n = 64;
        let mut x = vec![Vec3::zeros()];
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            x.push(Vec3::new(0.15 * a.cos(), 0.0, 0.15 * a.sin()));
        }
        let triangles: Vec<[u32; 3]> = (0..n as u32)
            .map(|k| [0, 1 + k, 1 + (k + 1) % n as u32])
            .collect();
        let shadow = Shadow::of(&x, &triangles, 0.2, 0.0005);
        let polygon = 0.5 * n as f64 * 0.15f64.powi(2) * (std::f64::consts::TAU / n as f64).sin();
        // In DC's units: over the standard ring between the 18 and 30 cm circles.
        let ring = std::f64::consts::PI * (0.15f64.powi(2) - 0.09f64.powi(2));
        assert!(
            (shadow.area() - polygon).abs() / ring < 0.002,
            "{} against {polygon}",
            shadow.area()
        );
        for lobes in [3, 6, 9, 14] {
            let r: Vec<f64> = (0..360)
                .map(|d| {
                    let a = (d as f64).to_radians();
                    0.12 + 0.02 * (lobes as f64 * a).cos() + 0.001 * (47.0 * a).sin()
                })
                .collect();
            assert_eq!(nodes(&r, 0.005), lobes, "{lobes} lobes");
        }
    }
}
