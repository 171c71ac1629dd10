//! Closed surfaces: whether a part is one (every directed edge once, and its reverse once),
//! the volume it encloses, and its shells turned outward when an exporter wound them
//! inside out.

use hooke_core::Vec3;
use std::collections::HashMap;

/// One id per distinct position, numbered in the order positions first appear: OBJ files
/// repeat vertices per face group, and the copies of one corner must count as one.
pub(crate) fn welded(vertices: &[Vec3]) -> Vec<u32> {
    let mut weld: HashMap<[u64; 3], u32> = HashMap::new();
    vertices
        .iter()
        .map(|v| {
            let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
            let next = weld.len() as u32;
            *weld.entry(key).or_insert(next)
        })
        .collect()
}

/// The volume a closed, consistently oriented surface encloses (the divergence theorem):
/// positive when its faces wind counter-clockwise seen from outside, negative when the
/// surface is inside out.
pub fn signed_volume(vertices: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

/// `triangles`, a closed, consistently oriented surface, with every shell (triangles
/// joined through shared corners) that encloses a negative volume turned outward, its
/// triangles' winding reversed. Exporters write inside-out solids now and then (flipped
/// normals); read as they are, everything outside such a table would be inside it, and a
/// cloth above it would be pulled through its top.
pub(crate) fn outward(vertices: &[Vec3], mut triangles: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    let ids = welded(vertices);
    let corners: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| t.map(|i| ids[i as usize]))
        .collect();
    let shell = shells(&corners, ids.len());
    let mut volume: HashMap<u32, f64> = HashMap::new();
    for (t, &s) in triangles.iter().zip(&shell) {
        *volume.entry(s).or_default() += signed_volume(vertices, std::slice::from_ref(t));
    }
    for (t, s) in triangles.iter_mut().zip(&shell) {
        if volume[s] < 0.0 {
            t.swap(1, 2);
        }
    }
    triangles
}

/// Per triangle of `triangles` (corners numbered below `count`), the shell it belongs to:
/// the triangles joined through shared corners share one number (a union-find's root).
pub(crate) fn shells(triangles: &[[u32; 3]], count: usize) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..count as u32).collect();
    fn root(parent: &mut [u32], mut k: u32) -> u32 {
        while parent[k as usize] != k {
            parent[k as usize] = parent[parent[k as usize] as usize];
            k = parent[k as usize];
        }
        k
    }
    for t in triangles {
        let a = root(&mut parent, t[0]);
        for &i in &t[1..] {
            let b = root(&mut parent, i);
            parent[b as usize] = a;
        }
    }
    triangles.iter().map(|t| root(&mut parent, t[0])).collect()
}

/// Why a part is not a closed, consistently oriented surface, if it is not: every directed
/// edge must appear once and its reverse once.
pub fn closedness_defect(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Option<String> {
    let ids = welded(vertices);
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (ids[t[k] as usize], ids[t[(k + 1) % 3] as usize]);
            *edges.entry((a, b)).or_default() += 1;
        }
    }
    let mut sorted: Vec<_> = edges.iter().collect();
    sorted.sort();
    for (&(a, b), &count) in sorted {
        if count > 1 {
            return Some(format!(
                "edge {a}-{b} is used {count} times in the same direction"
            ));
        }
        if !edges.contains_key(&(b, a)) {
            return Some(format!(
                "edge {a}-{b} has no opposite: the surface has a hole"
            ));
        }
    }
    None
}
