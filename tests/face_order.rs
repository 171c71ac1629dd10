//! A mesh body is the same fabric however its file writes each face: from any corner, wound
//! either way (docs/physics.md §1.1, "Meshes"). A quad whose diagonals are equal and an
//! n-gon's fan are cut from the face's lowest-numbered corner, so the cut does not follow
//! the file's corner order. A solid wound inward fills the same lattice, with a warning.

use crate::meshes::{build, dropped_on_the_table, folder, obj};
use hooke_core::Vec3;

/// A disc of radius 1 m: a 12-gon at its centre and 5 rings of quads around it. Every
/// quad is an isosceles trapezoid, whose two diagonals are equal, so its cut is a tie.
fn polar_disc() -> (Vec<Vec3>, Vec<Vec<u32>>) {
    let (sectors, rings) = (12usize, 6usize);
    let mut vertices = Vec::new();
    for r in 1..=rings {
        for s in 0..sectors {
            let a = std::f64::consts::TAU * s as f64 / sectors as f64;
            let radius = r as f64 / rings as f64;
            vertices.push(Vec3::new(radius * a.cos(), 0.0, radius * a.sin()));
        }
    }
    let id = |r: usize, s: usize| (r * sectors + s % sectors) as u32;
    let mut faces = vec![(0..sectors).map(|s| id(0, s)).collect::<Vec<u32>>()];
    for r in 0..rings - 1 {
        for s in 0..sectors {
            faces.push(vec![id(r, s), id(r + 1, s), id(r + 1, s + 1), id(r, s + 1)]);
        }
    }
    (vertices, faces)
}

/// The disc written three ways (as made; each face started on another corner; each face
/// wound the other way), dropped on the round table under block descent for 1 s: every
/// particle at the same bits from any starting corner and within 1e-9 m wound back, and the
/// cloth hangs over the table's edge.
#[test]
fn a_face_is_the_same_fabric_from_any_corner_and_either_winding() {
    let dir = folder("face-order");
    let (vertices, faces) = polar_disc();
    let started_elsewhere: Vec<Vec<u32>> = faces
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let shift = 1 + k % (f.len() - 1);
            f[shift..].iter().chain(&f[..shift]).copied().collect()
        })
        .collect();
    let wound_back: Vec<Vec<u32>> = faces
        .iter()
        .map(|f| f.iter().rev().copied().collect())
        .collect();
    let mut ends = Vec::new();
    for (name, faces) in [
        ("given", &faces),
        ("started-elsewhere", &started_elsewhere),
        ("wound-back", &wound_back),
    ] {
        let file = format!("{name}.obj");
        std::fs::write(dir.join(&file), obj(&vertices, faces)).unwrap();
        let mut scene = build(&dropped_on_the_table(&file, "cotton", ""), &dir).unwrap();
        scene.simulation.advance(60).unwrap();
        ends.push((name, scene.simulation.particles().x.clone()));
    }
    let (_, given) = &ends[0];
    for (name, x) in &ends[1..] {
        let moved = given
            .iter()
            .zip(x)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        if *name == "started-elsewhere" {
            assert!(
                given == x,
                "{name}: a particle is {moved:e} m from where the disc as written puts it"
            );
        } else {
            // Wound back, each triangle lists its corners the other way (the winding is
            // kept for normals), so a distance to it rounds differently: the same to
            // rounding, not to the bit. A different cut would be centimetres apart.
            assert!(
                moved < 1e-9,
                "{name}: a particle is {moved:e} m from where the disc as written puts it"
            );
        }
    }
    // It fell onto the table (top 0.6 m across at 1 m) and its rim hangs down, so what is
    // compared is a drape.
    let lowest = given.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    assert!(lowest < 0.8, "lowest {lowest} m");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The shipped peanut and a copy with every face wound inward fill the same lattice; the
/// inward one is warned about by its file (its drawn and exported faces show their backs),
/// the outward one is not.
#[test]
fn a_solid_wound_inward_is_filled_alike_and_named() {
    let dir = folder("inward");
    let text =
        std::fs::read_to_string(crate::common::root().join("assets/meshes/peanut.obj")).unwrap();
    let inward: String = text
        .lines()
        .map(|l| match l.strip_prefix("f ") {
            Some(corners) => {
                let mut c: Vec<&str> = corners.split_whitespace().collect();
                c.reverse();
                format!("f {}\n", c.join(" "))
            }
            None => format!("{l}\n"),
        })
        .collect();
    std::fs::write(dir.join("outward.obj"), &text).unwrap();
    std::fs::write(dir.join("inward.obj"), &inward).unwrap();
    let jelly = |file: &str| {
        build(
            &format!(
                r#"
name = "jelly"
[simulation]
integrator = "symplectic"
dt = 0.0005
duration = 0.01
every = 1
[[body]]
name = "peanut"
mass = 0.05
shape = {{ kind = "solid", path = "{file}", scale = [2.0, 2.0, 2.0], spacing = 0.1 }}
[body.springs.structural]
ks = 600.0
kd = 1.0
"#
            ),
            &dir,
        )
        .unwrap()
    };
    let (outward, inward) = (jelly("outward.obj"), jelly("inward.obj"));
    assert!(outward.warnings().is_empty(), "{:?}", outward.warnings());
    assert_eq!(
        outward.simulation.particles().x,
        inward.simulation.particles().x
    );
    let said = inward.warnings().join("\n");
    assert!(
        said.contains("inward.obj") && said.contains("wind inward"),
        "{said}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
