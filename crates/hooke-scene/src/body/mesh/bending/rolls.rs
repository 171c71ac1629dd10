//! What both bending models are tested on: a sheet rolled onto a cylinder, and the
//! energy of zero-rest springs.

use crate::body::mesh::bending::PairSprings;
use hooke_core::Vec3;

/// Energy of zero-rest springs at positions `x`.
pub(super) fn energy(springs: &[((u32, u32), f64)], x: &[Vec3]) -> f64 {
    springs
        .iter()
        .map(|((i, j), k)| 0.5 * k * (x[*i as usize] - x[*j as usize]).norm_squared())
        .sum()
}

/// Points of the x–z plane rolled onto a cylinder of curvature `kappa` about an axis
/// along z, keeping their lengths.
pub(super) fn rolled_about_z(x: &[Vec3], kappa: f64) -> Vec<Vec3> {
    x.iter()
        .map(|p| {
            let a = p.x * kappa;
            Vec3::new(a.sin() / kappa, (1.0 - a.cos()) / kappa, p.z)
        })
        .collect()
}

/// A bending model: the springs of rest positions, polygons and a rigidity.
pub(super) type Model = dyn Fn(&[Vec3], &[Vec<u32>], f64) -> PairSprings;

/// A 40 × 40 grid of points 1 cm apart, interior points jittered by up to `jitter` of the
/// spacing, each square cut along a random diagonal, given springs by `springs_of` for
/// `B = 5 µN·m`: that the flat sheet stores nothing, and the relative errors against
/// `½ B κ²` per area when it is rolled to `κ = 4/m` about z and about x.
pub(super) fn rolled_errors(jitter: f64, springs_of: &Model) -> [f64; 2] {
    let n = 40;
    let h = 0.01;
    let mut seed = 12345u64;
    let mut rand = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64) / ((1u64 << 53) as f64)
    };
    let mut flat = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let wobble = |r: f64| {
                if i == 0 || j == 0 || i == n - 1 || j == n - 1 {
                    0.0
                } else {
                    (r - 0.5) * jitter * h
                }
            };
            flat.push(Vec3::new(
                i as f64 * h + wobble(rand()),
                0.0,
                j as f64 * h + wobble(rand()),
            ));
        }
    }
    let id = |i: usize, j: usize| (i * n + j) as u32;
    let mut tris = Vec::new();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            if rand() < 0.5 {
                tris.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.push(vec![id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                tris.push(vec![id(i, j), id(i + 1, j), id(i, j + 1)]);
                tris.push(vec![id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    let b = 5e-6;
    let springs = springs_of(&flat, &tris, b);
    assert!(energy(&springs, &flat).abs() < 1e-9 * 0.5 * b * 16.0 * 0.39f64.powi(2));
    let kappa = 4.0;
    let area = ((n - 1) as f64 * h).powi(2);
    let want = 0.5 * b * kappa * kappa * area;
    // Rolled about an axis along z (curvature in x), then along x (curvature in z).
    let about_z = rolled_about_z(&flat, kappa);
    let about_x: Vec<Vec3> = flat
        .iter()
        .map(|p| {
            let a = p.z * kappa;
            Vec3::new(p.x, (1.0 - a.cos()) / kappa, a.sin() / kappa)
        })
        .collect();
    [about_z, about_x].map(|x| energy(&springs, &x) / want - 1.0)
}
