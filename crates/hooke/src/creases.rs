//! Hard edges of a drawn solid: where its faces meet at more than [`CREASE`], a corner takes
//! the normal of the faces on its own side only, so a jelly cube's faces are drawn flat up
//! to its edges instead of rounded across them (and a shadow lookup lifted along the normal
//! leaves each face, not the corner's average). A smooth surface, whose faces all meet
//! within the angle, keeps its vertex normals bit for bit.

use hooke_core::Vec3;
use hooke_render::Mesh;

/// The angle between two faces' normals beyond which the edge between them is drawn hard:
/// Blender's auto-smooth default is 30°; a deformed lattice's box corner stays near 90°.
const CREASE: f64 = 45.0;

/// Splits every vertex of `mesh` where faces meet beyond [`CREASE`] into one copy per
/// distinct normal of its corners (copies appended, with the vertex's colour), each corner's
/// normal the area-weighted sum of the vertex's faces within the angle of its own face.
pub(crate) fn split(mesh: &mut Mesh) {
    let face: Vec<Vec3> = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            (b - a).cross(&(c - a))
        })
        .collect();
    let unit: Vec<Vec3> = face
        .iter()
        .map(|n| n.try_normalize(0.0).unwrap_or_else(Vec3::zeros))
        .collect();
    let mut around: Vec<Vec<(usize, usize)>> = vec![Vec::new(); mesh.positions.len()];
    for (t, corners) in mesh.triangles.iter().enumerate() {
        for (k, &v) in corners.iter().enumerate() {
            around[v as usize].push((t, k));
        }
    }
    let smooth = CREASE.to_radians().cos();
    for (v, corners) in around.iter().enumerate() {
        let hard = corners
            .iter()
            .any(|&(t, _)| corners.iter().any(|&(u, _)| unit[t].dot(&unit[u]) < smooth));
        if !hard {
            continue;
        }
        // Each corner's normal from the faces on its side; equal normals share a vertex.
        let mut made: Vec<(Vec3, u32)> = Vec::new();
        for &(t, k) in corners {
            let sum: Vec3 = corners
                .iter()
                .filter(|&&(u, _)| unit[t].dot(&unit[u]) >= smooth)
                .map(|&(u, _)| face[u])
                .sum();
            let n = sum.try_normalize(0.0).unwrap_or(unit[t]);
            let index = match made.iter().find(|(m, _)| *m == n) {
                Some(&(_, i)) => i,
                None => {
                    let i = if made.is_empty() {
                        mesh.normals[v] = n;
                        v as u32
                    } else {
                        mesh.positions.push(mesh.positions[v]);
                        mesh.normals.push(n);
                        if !mesh.colors.is_empty() {
                            mesh.colors.push(mesh.colors[v]);
                        }
                        (mesh.positions.len() - 1) as u32
                    };
                    made.push((n, i));
                    i
                }
            };
            mesh.triangles[t][k] = index;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube of 12 triangles wound outward.
    fn cube() -> Mesh {
        let positions: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i >> 2 & 1) as f64, (i >> 1 & 1) as f64, (i & 1) as f64))
            .collect();
        let triangles = hooke_collide::BOX_FACES
            .iter()
            .map(|q| q.map(|k| k as u32))
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Mesh {
            normals: vec![Vec3::zeros(); 8],
            positions,
            triangles,
            ..Mesh::default()
        }
    }

    #[test]
    fn a_cube_is_drawn_with_each_face_flat() {
        let mut out = cube();
        split(&mut out);
        // Three faces meet at each corner: three copies of each.
        assert_eq!(out.positions.len(), 24);
        for t in &out.triangles {
            let [a, b, c] = t.map(|i| out.positions[i as usize]);
            let n = (b - a).cross(&(c - a)).normalize();
            for &i in t {
                assert!((out.normals[i as usize] - n).norm() < 1e-12, "{t:?}");
            }
        }
    }

    #[test]
    fn a_smooth_surface_keeps_its_vertices_and_normals() {
        // A shallow tent of two triangles, 20° apart: no hard edge.
        let lift = 20f64.to_radians().tan() * 0.5;
        let mut out = Mesh {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.5, lift, 1.0),
                Vec3::new(0.5, lift, -1.0),
            ],
            normals: vec![Vec3::y(); 4],
            triangles: vec![[0, 2, 1], [0, 1, 3]],
            ..Mesh::default()
        };
        split(&mut out);
        assert_eq!(out.positions.len(), 4);
        assert_eq!(out.normals, vec![Vec3::y(); 4]);
        assert_eq!(out.triangles, vec![[0, 2, 1], [0, 1, 3]]);
    }
}
