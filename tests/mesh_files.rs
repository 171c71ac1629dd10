//! A mesh body's files (docs/scenes.md): every vertex comes back in the file's order, pins
//! pick the vertices they name, and bad meshes are refused or warned about by file and line.

use crate::common::root;
use crate::meshes::{build, folder};

/// A PC2 written for a mesh body has the OBJ's vertex count, and its frame 0 is the OBJ's
/// positions in order, even where vertices are welded, unused or split by texture seams;
/// the OBJ beside it keeps the file's faces (a quad stays a quad) and texture coordinates.
#[test]
fn a_pc2_of_a_mesh_body_hands_back_every_vertex_in_order() {
    let dir = folder("pc2");
    // A quad, a triangle soup welded onto it, and a vertex in no face.
    let text = "v 0 0 0\nv 0.1 0 0\nv 0.1 0 0.1\nv 0 0 0.1\nv 5 5 5\n\
                v 0.1 0 0\nv 0.2 0 0\nv 0.1 0 0.1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
                f 1/1 2/2 3/3 4/4\nf 6/1 7/2 8/3\n";
    std::fs::write(dir.join("m.obj"), text).unwrap();
    let scene = build(
        r#"
name = "pc2"
[simulation]
integrator = "symplectic"
dt = 0.001
steps = 3
every = 1
[[body]]
name = "cloth"
mass = 0.01
shape = { kind = "mesh", path = "m.obj", weld = 1e-6 }
springs = { structural = { ks = 100.0, kd = 0.0 } }
"#,
        &dir,
    )
    .unwrap();
    assert_eq!(
        scene.simulation.particles().len(),
        5,
        "8 vertices, 2 welded, 1 unused"
    );
    let pc2 = dir.join("out.pc2");
    let mut sink = hooke::export::pc2::Pc2Export::create(&pc2, None, &scene).unwrap();
    use hooke::Sink;
    sink.frame(0, &scene).unwrap();
    Box::new(sink).finish().unwrap();
    let bytes = std::fs::read(&pc2).unwrap();
    let count = i32::from_le_bytes(bytes[16..20].try_into().unwrap());
    assert_eq!(count, 8);
    let file: Vec<[f32; 3]> = text
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let c: Vec<f32> = l[2..].split(' ').map(|w| w.parse().unwrap()).collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    for (k, want) in file.iter().enumerate() {
        let at = 32 + 12 * k;
        let got: Vec<f32> = (0..3)
            .map(|d| f32::from_le_bytes(bytes[at + 4 * d..at + 4 * d + 4].try_into().unwrap()))
            .collect();
        assert_eq!(&got[..], &want[..], "vertex {k}");
    }
    let mesh = std::fs::read_to_string(dir.join("out.obj")).unwrap();
    assert!(mesh.contains("f 1/1 2/2 3/3 4/4\n"), "{mesh}");
    assert_eq!(mesh.lines().filter(|l| l.starts_with("v ")).count(), 8);
    assert_eq!(mesh.lines().filter(|l| l.starts_with("vt ")).count(), 4);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Pins by the file's vertex indices, by a box or a ball in the file's coordinates, or by
/// an OBJ group, pick the vertices they say.
#[test]
fn pins_select_by_index_region_and_group() {
    let pinned = |pins: &str| -> Vec<usize> {
        let text = format!(
            r#"
name = "pins"
[simulation]
integrator = "symplectic"
dt = 0.001
steps = 1
every = 1
[[body]]
name = "curtain"
origin = [3.0, 2.0, 0.0]
pins = {pins}
shape = {{ kind = "mesh", path = "builtin:curtain.obj", scale = [2.0, 2.0, 2.0] }}
material = {{ preset = "cotton" }}
"#
        );
        let scene = build(&text, &root()).unwrap();
        let p = scene.simulation.particles();
        (0..p.len()).filter(|&i| p.is_pinned(i)).collect()
    };
    // The heading is the top row of quads: the first two rows of 25 vertices.
    assert_eq!(
        pinned("{ group = \"heading\" }"),
        (0..50).collect::<Vec<_>>()
    );
    assert_eq!(pinned("[0, 24]"), vec![0, 24]);
    // The file's coordinates, before scale: the top row is at y = 0, 5 cm apart.
    assert_eq!(
        pinned("{ box = [[-0.01, -0.01, -1.0], [0.06, 0.01, 1.0]] }"),
        vec![0, 1]
    );
    assert_eq!(
        pinned("{ sphere = { center = [0.6, 0.0, 0.0], radius = 0.001 } }"),
        vec![12]
    );
    for (pins, says) in [
        (
            "{ group = \"hem\" }",
            "no group 'hem'; its groups: heading, curtain",
        ),
        (
            "{ box = [[5.0, 5.0, 5.0], [6.0, 6.0, 6.0]] }",
            "holds no particle",
        ),
        ("[775]", "vertex 775 does not exist; the mesh has 775"),
        (
            "{ box = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]], group = \"heading\" }",
            "exactly one",
        ),
        (
            "{ box = [[-0.01, 0.01, -1.0], [0.06, -0.01, 1.0]] }",
            "y goes from 0.01 down to -0.01: swap them",
        ),
        (
            "{ sphere = { center = [0.6, 0.0, 0.0], radius = 0.0 } }",
            "pins.sphere.radius: a ball of pins needs a radius above zero, found 0",
        ),
    ] {
        let text = format!(
            "name = \"p\"\n[simulation]\nintegrator = \"symplectic\"\ndt = 0.001\nsteps = 1\nevery = 1\n\
             [[body]]\nname = \"c\"\npins = {pins}\nshape = {{ kind = \"mesh\", path = \"builtin:curtain.obj\" }}\n\
             material = {{ preset = \"cotton\" }}\n"
        );
        let e = build(&text, &root()).unwrap_err();
        assert!(
            e.contains("body[0] 'c'.pins") && e.contains(says),
            "{pins}: {e}"
        );
    }
}

/// Bad meshes get an error naming the file and line, or a warning saying what was done, and
/// nothing is half built.
#[test]
fn bad_meshes_are_refused_or_warned_about_by_file_and_line() {
    let dir = folder("bad");
    let scene = |shape: &str, mesh: &str| {
        std::fs::write(dir.join("bad.obj"), mesh).unwrap();
        build(
            &format!(
                "name = \"bad\"\n[simulation]\nintegrator = \"symplectic\"\ndt = 0.001\nsteps = 1\n\
                 every = 1\n[[body]]\nname = \"b\"\nmass = 0.01\nshape = {shape}\n\
                 springs = {{ structural = {{ ks = 10.0, kd = 0.0 }} }}\n"
            ),
            &dir,
        )
    };
    let cloth = "{ kind = \"mesh\", path = \"bad.obj\" }";
    let tri = "v 0 0 0\nv 1 0 0\nv 0 0 1\nv 0 1 0\nv 1 1 1\n";
    for (mesh, says) in [
        (
            format!("{tri}f 1 2 3\nf 1 2 4\nf 1 2 5\n"),
            "bad.obj:8: the edge between vertices 1 and 2 is shared by a third face",
        ),
        (
            "v 0 0 0\nv 1 0 nan\nv 0 0 1\nf 1 2 3\n".to_string(),
            "bad.obj:2",
        ),
        (
            "v 0 0 0\nv 1 0 inf\nv 0 0 1\nf 1 2 3\n".to_string(),
            "bad.obj:2",
        ),
        (format!("{tri}f 1 2 9\n"), "bad.obj:6: face vertex '9'"),
        (
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n".to_string(),
            "every face has zero area",
        ),
    ] {
        let e = scene(cloth, &mesh).unwrap_err();
        assert!(
            e.contains("body[0] 'b'.shape.path") && e.contains(says),
            "{e}"
        );
    }
    // A zero-area face and an unused vertex are dropped, and said.
    let built = scene(cloth, &format!("{tri}f 1 2 3\nf 1 1 2\n")).unwrap();
    let warnings = built.warnings().join("\n");
    assert!(
        warnings.contains("1 face with no area") && warnings.contains("line 7"),
        "{warnings}"
    );
    assert!(
        warnings.contains("2 vertices in no face (the first on line 4)"),
        "{warnings}"
    );
    // A weld that merges every face's corners names `weld`, not the path.
    let welded = "{ kind = \"mesh\", path = \"bad.obj\", weld = 2.0 }";
    let e = scene(welded, &format!("{tri}f 1 2 3\n")).unwrap_err();
    assert!(
        e.contains("body[0] 'b'.shape.weld")
            && e.contains("weld = 2 m merges the corners of every face")
            && e.contains("shortest edge is 1 m"),
        "{e}"
    );
    // A solid must be closed, and larger than a cell.
    let solid =
        |spacing: f64| format!("{{ kind = \"solid\", path = \"bad.obj\", spacing = {spacing} }}");
    let e = scene(&solid(0.1), &format!("{tri}f 1 2 3\nf 1 4 2\n")).unwrap_err();
    assert!(e.contains("closed") && e.contains("4 edges"), "{e}");
    let tetra = format!("{tri}f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    assert!(scene(&solid(0.1), &tetra).is_ok());
    let e = scene(&solid(2.0), &tetra).unwrap_err();
    assert!(e.contains("smaller than a cell"), "{e}");
    // The memory guard counts a mesh's vertices before they are stored.
    std::fs::remove_dir_all(&dir).unwrap();
}
