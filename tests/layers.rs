//! Two pieces of one mesh body (no face joins them) that start nearer than the body's
//! contact thickness are warned about, naming the body and the key that joins them; the
//! same pieces a few thicknesses apart, and a single sheet, are not (docs/physics.md §3.4).

use crate::meshes::{build, folder, obj};
use hooke_core::Vec3;

/// Two 0.5 m sheets of 10 × 10 quads, one above the other, `gap` apart, in one OBJ.
fn two_sheets(gap: f64) -> (Vec<Vec3>, Vec<Vec<u32>>) {
    let n = 11u32;
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    for y in [0.0, gap] {
        let base = vertices.len() as u32;
        for i in 0..n {
            for j in 0..n {
                vertices.push(Vec3::new(i as f64 * 0.05, y, j as f64 * 0.05));
            }
        }
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                let a = base + i * n + j;
                faces.push(vec![a, a + n, a + n + 1, a + 1]);
            }
        }
    }
    (vertices, faces)
}

#[test]
fn pieces_of_one_body_starting_within_its_thickness_are_named() {
    let dir = folder("layers");
    let scene = |file: &str| {
        format!(
            r#"
name = "layers"
[simulation]
integrator = "vbd"
dt = 0.016666666666666666
duration = 1.0
every = 1
[[body]]
name = "sheets"
origin = [0.0, 1.0, 0.0]
shape = {{ kind = "mesh", path = "{file}" }}
material = {{ preset = "cotton" }}
"#
        )
    };
    let warned = |gap: Option<f64>| {
        let (v, f) = match gap {
            Some(g) => two_sheets(g),
            None => {
                let (v, f) = two_sheets(0.0);
                (v[..121].to_vec(), f[..100].to_vec())
            }
        };
        std::fs::write(dir.join("sheets.obj"), obj(&v, &f)).unwrap();
        build(&scene("sheets.obj"), &dir).unwrap().warnings()
    };
    // The default thickness is 5 mm: at 1 mm the layers are within it, at 0 they coincide.
    for gap in [0.0, 0.001] {
        let said = warned(Some(gap)).join("\n");
        assert!(
            said.contains("body 'sheets'") && said.contains("shape.weld"),
            "gap {gap}: {said}"
        );
    }
    for gap in [Some(0.02), None] {
        let said = warned(gap);
        assert!(said.is_empty(), "gap {gap:?}: {said:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
