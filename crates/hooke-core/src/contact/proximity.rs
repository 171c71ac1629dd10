//! Closest points between the primitives that contacts are made of: a point, a segment, a
//! triangle and a circle. Pure geometry, no state; every routine returns the parameters of
//! its closest points (barycentric weights, segment parameters, an angle), so the contact
//! response can spread an impulse over the particles that span them.
//!
//! The point–triangle and segment–segment routines follow Ericson, *Real-Time Collision
//! Detection* (2005), §5.1.5 and §5.1.9.

use crate::collider::{Circle, Feature};
use crate::particles::Vec3;

/// Squared lengths below this are treated as zero (degenerate segments and triangles).
const TINY: f64 = 1e-30;

/// Barycentric weights `[wa, wb, wc]` (non-negative, summing to 1) of the point of triangle
/// `abc` nearest to `p`.
///
/// ```
/// use hooke_core::contact::proximity::point_triangle;
/// use hooke_core::Vec3;
/// let (a, b, c) = (Vec3::zeros(), Vec3::x(), Vec3::z());
/// let w = point_triangle(&Vec3::new(0.25, 1.0, 0.25), &a, &b, &c);
/// assert_eq!(w, [0.5, 0.25, 0.25]); // straight below: (0.25, 0, 0.25)
/// ```
pub fn point_triangle(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> [f64; 3] {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = va + vb + vc;
    if denom.abs() < TINY {
        // A degenerate (zero-area) triangle whose corner tests all failed: its longest edge.
        return degenerate_triangle(p, a, b, c);
    }
    let v = vb / denom;
    let w = vc / denom;
    [1.0 - v - w, v, w]
}

/// The nearest point of a zero-area triangle: the nearest of its three edges.
fn degenerate_triangle(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> [f64; 3] {
    let on = |s: &Vec3, t: &Vec3| {
        let d = t - s;
        let len2 = d.norm_squared();
        let u = if len2 < TINY {
            0.0
        } else {
            ((p - s).dot(&d) / len2).clamp(0.0, 1.0)
        };
        (u, (s + d * u - p).norm_squared())
    };
    let (u_ab, d_ab) = on(a, b);
    let (u_bc, d_bc) = on(b, c);
    let (u_ca, d_ca) = on(c, a);
    if d_ab <= d_bc && d_ab <= d_ca {
        [1.0 - u_ab, u_ab, 0.0]
    } else if d_bc <= d_ca {
        [0.0, 1.0 - u_bc, u_bc]
    } else {
        [u_ca, 0.0, 1.0 - u_ca]
    }
}

/// Parameters `(s, t)` in `[0, 1]` of the closest points `p1 + s (q1 - p1)` and
/// `p2 + t (q2 - p2)` of two segments. Parallel segments get one of their closest pairs.
///
/// ```
/// use hooke_core::contact::proximity::segment_segment;
/// use hooke_core::Vec3;
/// // Two crossing segments 1 m apart in y: the closest points are their midpoints.
/// let (s, t) = segment_segment(
///     &Vec3::new(-1.0, 0.0, 0.0), &Vec3::new(1.0, 0.0, 0.0),
///     &Vec3::new(0.0, 1.0, -1.0), &Vec3::new(0.0, 1.0, 1.0),
/// );
/// assert_eq!((s, t), (0.5, 0.5));
/// ```
pub fn segment_segment(p1: &Vec3, q1: &Vec3, p2: &Vec3, q2: &Vec3) -> (f64, f64) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    if a < TINY && e < TINY {
        return (0.0, 0.0);
    }
    if a < TINY {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(&r);
    if e < TINY {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(&d2);
    let denom = a * e - b * b;
    let mut s = if denom > TINY * a * e {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (s, t)
}

/// Where segment `pq` passes through triangle `abc`, if it does: the segment parameter and
/// the barycentric weights of the crossing point.
fn segment_through_triangle(
    p: &Vec3,
    q: &Vec3,
    a: &Vec3,
    b: &Vec3,
    c: &Vec3,
) -> Option<(f64, [f64; 3])> {
    let n = (b - a).cross(&(c - a));
    let dp = (p - a).dot(&n);
    let dq = (q - a).dot(&n);
    if (dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || dp == dq {
        return None;
    }
    let s = dp / (dp - dq);
    let x = p + (q - p) * s;
    // Sub-triangle areas along the normal give the weights; all of one sign means inside.
    let wa = (b - x).cross(&(c - x)).dot(&n);
    let wb = (c - x).cross(&(a - x)).dot(&n);
    let wc = (a - x).cross(&(b - x)).dot(&n);
    let sum = wa + wb + wc;
    if sum.abs() < TINY || wa < 0.0 || wb < 0.0 || wc < 0.0 {
        return None;
    }
    Some((s, [wa / sum, wb / sum, wc / sum]))
}

/// The closest points of segment `pq` and triangle `abc`: the segment parameter `s` and the
/// barycentric weights of the triangle's point. Where the segment passes through the
/// triangle, the crossing point (distance zero).
///
/// ```
/// use hooke_core::contact::proximity::segment_triangle;
/// use hooke_core::Vec3;
/// let (a, b, c) = (Vec3::zeros(), Vec3::x(), Vec3::z());
/// let (s, w) = segment_triangle(&Vec3::new(0.25, 1.0, 0.25), &Vec3::new(0.25, -1.0, 0.25), &a, &b, &c);
/// assert_eq!((s, w), (0.5, [0.5, 0.25, 0.25])); // through the triangle half way
/// ```
pub fn segment_triangle(p: &Vec3, q: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> (f64, [f64; 3]) {
    if let Some(hit) = segment_through_triangle(p, q, a, b, c) {
        return hit;
    }
    let at = |s: f64, w: [f64; 3]| {
        let x = p + (q - p) * s;
        let y = a * w[0] + b * w[1] + c * w[2];
        ((x - y).norm_squared(), s, w)
    };
    let mut best = at(0.0, point_triangle(p, a, b, c));
    let mut keep = |cand: (f64, f64, [f64; 3])| {
        if cand.0 < best.0 {
            best = cand;
        }
    };
    keep(at(1.0, point_triangle(q, a, b, c)));
    let (s, t) = segment_segment(p, q, a, b);
    keep(at(s, [1.0 - t, t, 0.0]));
    let (s, t) = segment_segment(p, q, b, c);
    keep(at(s, [0.0, 1.0 - t, t]));
    let (s, t) = segment_segment(p, q, c, a);
    keep(at(s, [t, 0.0, 1.0 - t]));
    (best.1, best.2)
}

impl Circle {
    /// Two unit vectors spanning the circle's plane, `u × v = axis`.
    fn basis(&self) -> (Vec3, Vec3) {
        let helper = if self.axis.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        let u = self.axis.cross(&helper).normalize();
        let v = self.axis.cross(&u);
        (u, v)
    }

    /// The point of the circle at angle `theta` in its [`Circle::basis`].
    fn at(&self, (u, v): (Vec3, Vec3), theta: f64) -> Vec3 {
        self.center + (u * theta.cos() + v * theta.sin()) * self.radius
    }
}

impl Circle {
    /// A lower bound on the distance between the circle and triangle `abc`, cheap enough to
    /// spare the exact search for triangles that are clearly apart. A point at height `y`
    /// above the circle's plane and radius `r` from its axis is `√((r - R)² + y²)` from the
    /// circle, and each term is at least its least value over the triangle: `y` from the
    /// corners (zero when they straddle the plane), `r` from the triangle's projection on the
    /// plane (its largest at a corner, its least by a 2-D nearest-point search).
    pub fn distance_bound(&self, a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
        let (u, v) = self.basis();
        let local = |p: &Vec3| {
            let d = p - self.center;
            (Vec3::new(d.dot(&u), 0.0, d.dot(&v)), d.dot(&self.axis))
        };
        let ((pa, ya), (pb, yb), (pc, yc)) = (local(a), local(b), local(c));
        let (lo, hi) = (ya.min(yb).min(yc), ya.max(yb).max(yc));
        let dy = if lo > 0.0 {
            lo
        } else if hi < 0.0 {
            -hi
        } else {
            0.0
        };
        let r_max = pa.norm().max(pb.norm()).max(pc.norm());
        let w = point_triangle(&Vec3::zeros(), &pa, &pb, &pc);
        let r_min = (pa * w[0] + pb * w[1] + pc * w[2]).norm();
        let dr = (r_min - self.radius).max(self.radius - r_max).max(0.0);
        (dr * dr + dy * dy).sqrt()
    }
}

/// Golden-section steps refining the nearest angle: the bracket (two sample spacings, a few
/// hundredths of a radian for a cloth triangle at a table's rim) shrinks by 0.618 a step,
/// to below 1e-6 of itself in 30 steps: the point moves well under a micrometre along the
/// rim, and the distance, flat at its minimum, by far less.
const GOLDEN_STEPS: usize = 30;

/// The closest points of `circle` and triangle `abc`: the point on the circle and the
/// barycentric weights of the triangle's point.
///
/// The circle is exact (not a polygon): the distance is minimised over the arc that the
/// triangle's corners span as seen from the circle's axis (the whole circle when they
/// surround it), by sampling and then golden-section refinement of the best sample's bracket.
pub(crate) fn circle_triangle(circle: &Circle, a: &Vec3, b: &Vec3, c: &Vec3) -> (Vec3, [f64; 3]) {
    let basis = circle.basis();
    let (u, v) = basis;
    let angle = |p: &Vec3| {
        let d = p - circle.center;
        d.dot(&v).atan2(d.dot(&u))
    };
    // The arc the corners span, measured from the first corner's angle.
    let t0 = angle(a);
    let wrap = |t: f64| {
        (t - t0 + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    let (t1, t2) = (wrap(angle(b)), wrap(angle(c)));
    let lo = 0.0_f64.min(t1).min(t2);
    let hi = 0.0_f64.max(t1).max(t2);
    // A triangle that surrounds the axis spans the whole circle; otherwise its arc plus a
    // margin, since the nearest rim point can lie a little outside the corners' arc.
    let (start, span) = if hi - lo > std::f64::consts::PI {
        (t0, std::f64::consts::TAU)
    } else {
        let margin = 0.25 * (hi - lo) + 1e-3;
        (t0 + lo - margin, hi - lo + 2.0 * margin)
    };
    let dist = |theta: f64| {
        let x = circle.at(basis, theta);
        let w = point_triangle(&x, a, b, c);
        ((a * w[0] + b * w[1] + c * w[2] - x).norm_squared(), w, x)
    };
    let samples = if span >= std::f64::consts::TAU { 64 } else { 6 };
    let step = span / samples as f64;
    let mut best = (f64::INFINITY, 0.0);
    for k in 0..=samples {
        let theta = start + step * k as f64;
        let d = dist(theta).0;
        if d < best.0 {
            best = (d, theta);
        }
    }
    let (mut lo, mut hi) = (best.1 - step, best.1 + step);
    const INV_PHI: f64 = 0.618_033_988_749_894_9;
    let mut m1 = hi - (hi - lo) * INV_PHI;
    let mut m2 = lo + (hi - lo) * INV_PHI;
    let (mut f1, mut f2) = (dist(m1).0, dist(m2).0);
    for _ in 0..GOLDEN_STEPS {
        if f1 <= f2 {
            hi = m2;
            m2 = m1;
            f2 = f1;
            m1 = hi - (hi - lo) * INV_PHI;
            f1 = dist(m1).0;
        } else {
            lo = m1;
            m1 = m2;
            f1 = f2;
            m2 = lo + (hi - lo) * INV_PHI;
            f2 = dist(m2).0;
        }
    }
    let (_, w, x) = dist(0.5 * (lo + hi));
    (x, w)
}

/// The point of collider feature `f` nearest triangle `abc`, and the triangle's weights of
/// its point nearest to it.
pub(crate) fn feature_triangle(
    f: &crate::collider::Feature,
    a: &Vec3,
    b: &Vec3,
    c: &Vec3,
) -> (Vec3, [f64; 3]) {
    match f {
        crate::collider::Feature::Segment([p, q]) => {
            let (s, w) = segment_triangle(p, q, a, b, c);
            (p + (q - p) * s, w)
        }
        crate::collider::Feature::Circle(circle) => circle_triangle(circle, a, b, c),
        crate::collider::Feature::Ball { center, radius } => {
            ball_triangle(center, *radius, a, b, c)
        }
    }
}

/// The closest points of the sphere of `radius` about `center` and triangle `abc`: the
/// point on the sphere and the barycentric weights of the triangle's point (the
/// triangle's point nearest the centre; the sphere's point on the ray to it, or along the
/// triangle's normal when the centre lies on the triangle).
pub(crate) fn ball_triangle(
    center: &Vec3,
    radius: f64,
    a: &Vec3,
    b: &Vec3,
    c: &Vec3,
) -> (Vec3, [f64; 3]) {
    let w = point_triangle(center, a, b, c);
    let q = a * w[0] + b * w[1] + c * w[2];
    let out = (q - center)
        .try_normalize(0.0)
        .or_else(|| (b - a).cross(&(c - a)).try_normalize(0.0))
        .unwrap_or_else(Vec3::y);
    (center + out * radius, w)
}

/// The closest points of a collider feature and triangle `t` at `x`: the feature's point
/// and the triangle's barycentric weights; `None` when a cheap bound shows they are farther
/// apart than `within`.
pub(super) fn feature_gap(
    feature: &Feature,
    t: &[u32; 3],
    x: &[Vec3],
    within: f64,
) -> Option<(Vec3, [f64; 3])> {
    let (a, b, c) = (&x[t[0] as usize], &x[t[1] as usize], &x[t[2] as usize]);
    let (anchor, w) = match feature {
        Feature::Segment([p, q]) => {
            let (s, w) = segment_triangle(p, q, a, b, c);
            (p + (q - p) * s, w)
        }
        Feature::Circle(circle) if circle.distance_bound(a, b, c) >= within => return None,
        Feature::Circle(circle) => circle_triangle(circle, a, b, c),
        Feature::Ball { center, radius } => ball_triangle(center, *radius, a, b, c),
    };
    let gap = a * w[0] + b * w[1] + c * w[2] - anchor;
    (gap.norm_squared() < within * within).then_some((anchor, w))
}

/// The distance from `p` to triangle `abc`.
pub(crate) fn point_triangle_distance(p: &Vec3, [a, b, c]: [&Vec3; 3]) -> f64 {
    let w = point_triangle(p, a, b, c);
    (p - (a * w[0] + b * w[1] + c * w[2])).norm()
}

/// The distance between segments `p1q1` and `p2q2`.
pub(crate) fn segment_distance([p1, q1, p2, q2]: [&Vec3; 4]) -> f64 {
    let (s, t) = segment_segment(p1, q1, p2, q2);
    ((p1 + (q1 - p1) * s) - (p2 + (q2 - p2) * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri_point(w: [f64; 3], a: &Vec3, b: &Vec3, c: &Vec3) -> Vec3 {
        a * w[0] + b * w[1] + c * w[2]
    }

    /// Brute force: the nearest of many points spread over the triangle.
    fn brute_point_triangle(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
        let n = 200;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let x = tri_point([1.0 - u - v, u, v], a, b, c);
                best = best.min((x - p).norm());
            }
        }
        best
    }

    /// A small deterministic generator, so the cases are the same on every run.
    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
    }

    fn rand_vec(seed: &mut u64) -> Vec3 {
        Vec3::new(lcg(seed), lcg(seed), lcg(seed))
    }

    #[test]
    fn point_triangle_matches_brute_force() {
        let mut seed = 7;
        for _ in 0..200 {
            let (p, a, b, c) = (
                rand_vec(&mut seed) * 2.0,
                rand_vec(&mut seed),
                rand_vec(&mut seed),
                rand_vec(&mut seed),
            );
            let w = point_triangle(&p, &a, &b, &c);
            assert!(w.iter().all(|&x| (-1e-12..=1.0 + 1e-12).contains(&x)));
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let d = (tri_point(w, &a, &b, &c) - p).norm();
            // The grid's spacing bounds how much nearer the brute force can get.
            let brute = brute_point_triangle(&p, &a, &b, &c);
            assert!(d <= brute + 1e-12, "{d} > {brute}");
            assert!(brute - d < 0.02, "{d} vs brute {brute}");
        }
    }

    #[test]
    fn segment_segment_is_no_farther_than_sampled_pairs() {
        let mut seed = 11;
        for _ in 0..200 {
            let (p1, q1, p2, q2) = (
                rand_vec(&mut seed),
                rand_vec(&mut seed),
                rand_vec(&mut seed),
                rand_vec(&mut seed),
            );
            let (s, t) = segment_segment(&p1, &q1, &p2, &q2);
            let d = (p1 + (q1 - p1) * s - p2 - (q2 - p2) * t).norm();
            for i in 0..=50 {
                for j in 0..=50 {
                    let (s, t) = (i as f64 / 50.0, j as f64 / 50.0);
                    let e = (p1 + (q1 - p1) * s - p2 - (q2 - p2) * t).norm();
                    assert!(d <= e + 1e-12, "{d} > {e}");
                }
            }
        }
    }

    #[test]
    fn a_segment_through_a_triangle_is_at_distance_zero() {
        let (a, b, c) = (Vec3::zeros(), Vec3::x(), Vec3::z());
        let (s, w) = segment_triangle(
            &Vec3::new(0.2, 1.0, 0.2),
            &Vec3::new(0.2, -3.0, 0.2),
            &a,
            &b,
            &c,
        );
        assert!((s - 0.25).abs() < 1e-15);
        let x = tri_point(w, &a, &b, &c);
        assert!((x - Vec3::new(0.2, 0.0, 0.2)).norm() < 1e-15);
    }

    #[test]
    fn segment_triangle_is_no_farther_than_its_parts() {
        let mut seed = 5;
        for _ in 0..200 {
            let (p, q, a, b, c) = (
                rand_vec(&mut seed),
                rand_vec(&mut seed),
                rand_vec(&mut seed),
                rand_vec(&mut seed),
                rand_vec(&mut seed),
            );
            let (s, w) = segment_triangle(&p, &q, &a, &b, &c);
            let d = (p + (q - p) * s - tri_point(w, &a, &b, &c)).norm();
            for i in 0..=40 {
                let x = p + (q - p) * (i as f64 / 40.0);
                let e = (tri_point(point_triangle(&x, &a, &b, &c), &a, &b, &c) - x).norm();
                assert!(d <= e + 1e-12, "{d} > {e}");
            }
        }
    }

    #[test]
    fn circle_triangle_finds_the_rim_under_a_draped_triangle() {
        // The rim of a table of radius 0.6 at y = 1, and a cloth triangle folded over it.
        let rim = Circle {
            center: Vec3::new(0.0, 1.0, 0.0),
            axis: Vec3::y(),
            radius: 0.6,
        };
        let a = Vec3::new(0.58, 1.004, -0.03);
        let b = Vec3::new(0.58, 1.004, 0.03);
        let c = Vec3::new(0.64, 0.95, 0.0);
        let (x, w) = circle_triangle(&rim, &a, &b, &c);
        assert!(((x - rim.center).norm() - 0.6).abs() < 1e-12);
        let d = (tri_point(w, &a, &b, &c) - x).norm();
        // Against a dense polygon of the rim: never farther than its best vertex.
        let mut best = f64::INFINITY;
        for k in 0..200_000 {
            let t = std::f64::consts::TAU * k as f64 / 200_000.0;
            let y = Vec3::new(0.6 * t.cos(), 1.0, 0.6 * t.sin());
            best = best.min((tri_point(point_triangle(&y, &a, &b, &c), &a, &b, &c) - y).norm());
        }
        assert!(d <= best + 1e-12 && best - d < 1e-6, "{d} vs {best}");
        assert!(d < 0.02, "{d}");
        assert!(rim.distance_bound(&a, &b, &c) <= d);
    }

    #[test]
    fn the_circle_bound_never_exceeds_the_distance() {
        let mut seed = 3;
        let rim = Circle {
            center: Vec3::new(0.1, 0.2, -0.1),
            axis: Vec3::new(0.3, 1.0, 0.2).normalize(),
            radius: 0.6,
        };
        let mut useful = 0;
        for _ in 0..300 {
            let a = rand_vec(&mut seed) * 0.8;
            let (b, c) = (a + rand_vec(&mut seed) * 0.1, a + rand_vec(&mut seed) * 0.1);
            let (x, w) = circle_triangle(&rim, &a, &b, &c);
            let d = (tri_point(w, &a, &b, &c) - x).norm();
            let bound = rim.distance_bound(&a, &b, &c);
            assert!(bound <= d + 1e-12, "bound {bound} > distance {d}");
            useful += usize::from(bound > 0.5 * d);
        }
        // It is a bound worth having: for most small triangles within a factor two.
        assert!(useful > 150, "{useful}");
    }
}
