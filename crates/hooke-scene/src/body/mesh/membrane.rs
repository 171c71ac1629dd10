//! A fabric's membrane on any polygon: the edge springs whose stiffness best reproduces, in
//! each face, the stretch and shear per unit width that the material gives a grid
//! (docs/physics.md §1.1, "Meshes").
//!
//! A spring of stiffness `k` and rest length `L` along the unit direction `d` of a face of
//! area `A`, stretched by a small uniform strain `ε`, stores `½ k L² (dᵀ ε d)²`: per area, the
//! membrane stiffness tensor `k L² / A · d⊗d⊗d⊗d`. The grid's springs give, in the warp and
//! weft directions `w` and `f`, `stretch (w⁴ + f⁴) + 2 shear ((w+f)/√2)⁴ + 2 shear ((w−f)/√2)⁴`:
//! components `[stretch + shear, 0, shear, 0, stretch + shear]` on `(xxxx, xxxy, xxyy, xyyy,
//! yyyy)`. Each face's springs (a triangle's three edges, a quad's four and both diagonals)
//! take the non-negative stiffnesses that come nearest it in the tensor's norm.

use hooke_core::Vec3;

/// The fourth-order tensor components `(xxxx, xxxy, xxyy, xyyy, yyyy)` of a direction at
/// angle `(c, s)` in the warp–weft frame.
fn quartic(c: f64, s: f64) -> [f64; 5] {
    [
        c.powi(4),
        c.powi(3) * s,
        c * c * s * s,
        c * s.powi(3),
        s.powi(4),
    ]
}

/// Each component's count in the full tensor (the norm's weights).
const MULTIPLICITY: [f64; 5] = [1.0, 4.0, 6.0, 4.0, 1.0];

/// The warp direction of a face with normal `n`: the body's local x projected onto the
/// face, or its local z where x is nearly along the normal.
pub(crate) fn warp(n: &Vec3) -> Vec3 {
    let x = Vec3::x();
    let p = x - n * n.dot(&x);
    if p.norm() > 0.5 {
        p.normalize()
    } else {
        let z = Vec3::z();
        (z - n * n.dot(&z)).normalize()
    }
}

/// The stiffness of each of `springs` (pairs of corner positions) of one face of `area`
/// and unit normal `n`, for a fabric of `stretch` and `shear` (N/m).
pub(crate) fn fit(
    springs: &[(Vec3, Vec3)],
    area: f64,
    n: &Vec3,
    stretch: f64,
    shear: f64,
) -> Vec<f64> {
    let w = warp(n);
    let f = n.cross(&w);
    let target = [stretch + shear, 0.0, shear, 0.0, stretch + shear].map(|t| t * area);
    // Column e: spring e's tensor per unit stiffness, `L² d⁴`.
    let columns: Vec<[f64; 5]> = springs
        .iter()
        .map(|(a, b)| {
            let d = b - a;
            let (c, s) = (d.dot(&w), d.dot(&f));
            let l2 = c * c + s * s;
            let l = l2.sqrt();
            quartic(c / l, s / l).map(|q| q * l2)
        })
        .collect();
    let m = columns.len();
    // A tiny ridge keeps the split between parallel springs (a quad's opposite sides) even.
    let scale = columns
        .iter()
        .map(|c| dot(c, c))
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let ridge = 1e-9 * scale;
    let mut best: Option<(f64, Vec<f64>)> = None;
    // Non-negative least squares by trying every set of active springs (at most 2⁶).
    for set in 1u32..(1 << m) {
        let active: Vec<usize> = (0..m).filter(|e| set & (1 << e) != 0).collect();
        let k = active.len();
        let mut a = nalgebra::DMatrix::<f64>::zeros(k, k);
        let mut rhs = nalgebra::DVector::<f64>::zeros(k);
        for (r, &i) in active.iter().enumerate() {
            for (c, &j) in active.iter().enumerate() {
                a[(r, c)] = dot(&columns[i], &columns[j]) + if r == c { ridge } else { 0.0 };
            }
            rhs[r] = dot(&columns[i], &target);
        }
        let Some(x) = a.lu().solve(&rhs) else {
            continue;
        };
        if x.iter().any(|&v| v < 0.0 || !v.is_finite()) {
            continue;
        }
        let mut stiffness = vec![0.0; m];
        for (r, &i) in active.iter().enumerate() {
            stiffness[i] = x[r];
        }
        let mut residual = 0.0;
        for q in 0..5 {
            let sum: f64 = (0..m).map(|e| stiffness[e] * columns[e][q]).sum();
            residual += MULTIPLICITY[q] * (sum - target[q]).powi(2);
        }
        residual += ridge * stiffness.iter().map(|s| s * s).sum::<f64>();
        if best.as_ref().is_none_or(|(r, _)| residual < *r) {
            best = Some((residual, stiffness));
        }
    }
    best.map_or(vec![0.0; m], |(_, k)| k)
}

/// The tensor norm's inner product.
fn dot(a: &[f64; 5], b: &[f64; 5]) -> f64 {
    (0..5).map(|q| MULTIPLICITY[q] * a[q] * b[q]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square face's springs are the grid's: half the stretch on each side (a side is
    /// shared by two faces) and the shear on each diagonal.
    #[test]
    fn a_square_gets_the_grids_springs() {
        let h = 0.02;
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(h, 0.0, 0.0),
            Vec3::new(h, 0.0, h),
            Vec3::new(0.0, 0.0, h),
        ];
        let springs = [
            (p[0], p[1]),
            (p[1], p[2]),
            (p[2], p[3]),
            (p[3], p[0]),
            (p[0], p[2]),
            (p[1], p[3]),
        ];
        let k = fit(&springs, h * h, &Vec3::y(), 1000.0, 50.0);
        for (e, want) in [500.0, 500.0, 500.0, 500.0, 50.0, 50.0].iter().enumerate() {
            assert!((k[e] - want).abs() < 1e-4 * want, "{e}: {} vs {want}", k[e]);
        }
    }
}
