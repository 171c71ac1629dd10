//! Whether triangles cross, written from signed volumes alone, independent of the solver's
//! proximity code: the contact checks of the report and of the validation suite use it.

use hooke_core::Vec3;

/// A triangle by its corners.
pub type Tri = [Vec3; 3];

/// `(b - a) × (c - a) · (d - a)`: positive when `d` is on the side the triangle `abc` faces.
fn orient(a: &Vec3, b: &Vec3, c: &Vec3, d: &Vec3) -> f64 {
    (b - a).cross(&(c - a)).dot(&(d - a))
}

/// Whether segment `pq` passes through the inside of triangle `t` (touching is not
/// crossing: such configurations have measure zero, and the thickness keeps cloth far from
/// them).
fn segment_crosses(p: &Vec3, q: &Vec3, t: &Tri) -> bool {
    let (sp, sq) = (
        orient(&t[0], &t[1], &t[2], p),
        orient(&t[0], &t[1], &t[2], q),
    );
    if !((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0)) {
        return false;
    }
    let e = [
        orient(p, q, &t[0], &t[1]),
        orient(p, q, &t[1], &t[2]),
        orient(p, q, &t[2], &t[0]),
    ];
    e.iter().all(|&s| s > 0.0) || e.iter().all(|&s| s < 0.0)
}

/// Two triangles cross when an edge of one passes through the other.
pub fn triangles_cross(a: &Tri, b: &Tri) -> bool {
    (0..3).any(|k| segment_crosses(&a[k], &a[(k + 1) % 3], b))
        || (0..3).any(|k| segment_crosses(&b[k], &b[(k + 1) % 3], a))
}

fn bounds(t: &Tri) -> (Vec3, Vec3) {
    (t[0].inf(&t[1]).inf(&t[2]), t[0].sup(&t[1]).sup(&t[2]))
}

fn overlap(a: &(Vec3, Vec3), b: &(Vec3, Vec3)) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

/// Crossing pairs in one state: (cloth–collider, cloth–cloth). `cloth` holds each surface
/// triangle with its corner indices (triangles sharing a corner are neighbours, not a
/// crossing); `colliders` the colliders' triangles.
pub fn count(cloth: &[(Tri, [u32; 3])], colliders: &[Tri]) -> (usize, usize) {
    let cloth_boxes: Vec<_> = cloth.iter().map(|(t, _)| bounds(t)).collect();
    let mut against_colliders = 0;
    for c in colliders {
        let cb = bounds(c);
        for (k, (t, _)) in cloth.iter().enumerate() {
            if overlap(&cb, &cloth_boxes[k]) && triangles_cross(t, c) {
                against_colliders += 1;
            }
        }
    }
    (against_colliders, cloth_pairs(cloth).len())
}

/// The cloth triangles that cross each other in one state, as pairs of indices into
/// `cloth` (see [`count`]), lower index first, in the order a sweep along x finds them.
pub fn cloth_pairs(cloth: &[(Tri, [u32; 3])]) -> Vec<(usize, usize)> {
    let boxes: Vec<_> = cloth.iter().map(|(t, _)| bounds(t)).collect();
    let mut order: Vec<usize> = (0..cloth.len()).collect();
    order.sort_by(|&a, &b| boxes[a].0.x.total_cmp(&boxes[b].0.x));
    let mut pairs = Vec::new();
    for (i, &a) in order.iter().enumerate() {
        for &b in &order[i + 1..] {
            if boxes[b].0.x > boxes[a].1.x {
                break;
            }
            let (ta, ia) = &cloth[a];
            let (tb, ib) = &cloth[b];
            if ia.iter().any(|v| ib.contains(v)) {
                continue;
            }
            if overlap(&boxes[a], &boxes[b]) && triangles_cross(ta, tb) {
                pairs.push((a.min(b), a.max(b)));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_through_another_crosses_and_one_beside_it_does_not() {
        let flat = [
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let upright = [
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.1, 1.0, 0.1),
        ];
        assert!(triangles_cross(&flat, &upright));
        let above = upright.map(|p| p + Vec3::new(0.0, 2.5, 0.0));
        assert!(!triangles_cross(&flat, &above));
        assert_eq!(count(&[(flat, [0, 1, 2])], &[upright]), (1, 0));
    }
}
