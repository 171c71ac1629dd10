//! Air (docs/physics.md §1): a sheet falling face-on reaches its terminal speed, edge-on it
//! falls as in vacuum, lift pushes a tilted sheet the way the formula says, and a hanging
//! cloth in a side wind is displaced downwind, the reversed wind giving the mirror image.

use crate::common::root;
use hooke::report::{RHO, falling_sheet as sheet};
use hooke_core::{Integrator, Simulation, Vec3};
use hooke_scene::spec::{AirSpec, Finite, Positive};

const G: f64 = 9.81;

fn mean(v: &[Vec3]) -> Vec3 {
    v.iter().sum::<Vec3>() / v.len() as f64
}

#[test]
fn a_sheet_falling_face_on_reaches_the_terminal_speed() {
    // 50 g on 1 m²: v_t = √(2 m g / (ρ C_d A)) = 0.8949 m/s, reached within τ ≈ v_t/g.
    let (mass, area) = (0.05, 1.0);
    let (p, model) = sheet(
        9,
        1.0,
        mass,
        Vec3::new(0.0, 10.0, 0.0),
        (Vec3::x(), Vec3::z()),
    );
    let mut sim = Simulation::new(p, model, Integrator::Symplectic, 1e-3);
    sim.advance(2000).unwrap();
    let v = mean(&sim.particles().v);
    let terminal = (2.0 * mass * G / (RHO * 1.0 * area)).sqrt();
    assert!((terminal - 0.8949).abs() < 1e-4);
    let error = (-v.y - terminal).abs() / terminal;
    eprintln!(
        "falls at {} m/s; terminal {terminal} m/s; error {error:e}",
        -v.y
    );
    assert!(
        error < 0.01,
        "falls at {} m/s, terminal {terminal} m/s",
        -v.y
    );
    // Still flat and level: every particle at the same height within a micrometre.
    let ys: Vec<f64> = sim.particles().x.iter().map(|x| x.y).collect();
    let spread =
        ys.iter().cloned().fold(f64::MIN, f64::max) - ys.iter().cloned().fold(f64::MAX, f64::min);
    assert!(spread < 1e-6, "the sheet bent by {spread} m");
    // Without air it would be falling at g t = 19.6 m/s.
    assert!(v.x.abs() < 1e-12 && v.z.abs() < 1e-12);
}

#[test]
fn a_sheet_falling_edge_on_falls_as_in_vacuum() {
    // The sheet spans x and y: its normal is z, the fall is along the surface.
    let build = |air: bool| {
        let (p, mut model) = sheet(
            9,
            1.0,
            0.05,
            Vec3::new(0.0, 10.0, 0.0),
            (Vec3::x(), Vec3::y()),
        );
        if !air {
            model.air = None;
        }
        Simulation::new(p, model, Integrator::Rk4, 1e-3)
    };
    let (mut with, mut without) = (build(true), build(false));
    with.advance(1000).unwrap();
    without.advance(1000).unwrap();
    let v = mean(&with.particles().v);
    assert!((v.y + G).abs() < 1e-9, "fell at {} m/s after 1 s", -v.y);
    for (a, b) in with.particles().x.iter().zip(&without.particles().x) {
        assert!((a - b).norm() <= 1e-12, "{a} vs {b}");
    }
}

#[test]
fn lift_pushes_a_tilted_sheet_sideways_as_the_formula_says() {
    // Tilted 30° about z: in-plane directions (cos 30°, sin 30°, 0) and z, normal
    // n = (-sin 30°, cos 30°, 0). Falling at speed s, u = (0, -s, 0), u·n = -s cos 30°, and
    // |u|² n - (u·n) u = s² (-sin 30°, 0, 0), so lift is
    // -½ ρ C_l A (u·n) s² (-sin 30°, 0, 0) / s = ½ ρ C_l A s² cos 30° sin 30° · (-1, 0, 0):
    // towards -x, and no vertical component.
    let tilt = 30f64.to_radians();
    let along = Vec3::new(tilt.cos(), tilt.sin(), 0.0);
    let run = |lift: f64| {
        let (p, mut model) = sheet(9, 1.0, 0.05, Vec3::new(0.0, 10.0, 0.0), (along, Vec3::z()));
        model.aero[0].lift = lift;
        let mut sim = Simulation::new(p, model, Integrator::Rk4, 5e-4);
        sim.advance(600).unwrap();
        (mean(&sim.particles().x), mean(&sim.particles().v))
    };
    let (x0, v0) = run(0.0);
    let (x1, v1) = run(1.0);
    // Pressure drag alone already pushes a tilted plate along its normal's -x; lift adds to it.
    assert!(x0.x < 0.0, "drag drift {}", x0.x);
    let drift = x1.x - x0.x;
    eprintln!(
        "x drift after 0.3 s: drag only {} m, with lift {} m",
        x0.x, x1.x
    );
    assert!(drift < -1e-3, "lift moved the sheet by {drift} m in x");
    // Sideways only: the vertical velocity changes far less than the horizontal one.
    assert!((v1.x - v0.x).abs() > 5.0 * (v1.y - v0.y).abs() || (v1.y - v0.y).abs() < 1e-3);
    assert!(x1.z.abs() < 1e-12 && x0.z.abs() < 1e-12);
    // Its formula's value at the start of the fall, from the library: along -x.
    let f = hooke_core::forces::air::triangle_force(
        RHO,
        0.0,
        1.0,
        &[Vec3::zeros(), along, Vec3::z()],
        &[Vec3::new(0.0, -2.0, 0.0); 3],
        &Vec3::zeros(),
    );
    let expected = 0.5 * RHO * 0.5 * 4.0 * tilt.cos() * tilt.sin();
    assert!((f - Vec3::new(-expected, 0.0, 0.0)).norm() < 1e-12, "{f}");
}

/// The hanging cloth, but hung straight down in the plane z = 0 from the start and with a
/// steady wind along z.
fn hanging_in_wind(wind_z: f64) -> hooke_scene::Scene {
    let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    let flat = spec.build(&root()).unwrap();
    let x = &flat.simulation.particles().x;
    let body = &mut spec.bodies[0];
    // The pinned edge runs along z at the lowest x; each particle hangs as far below it as
    // it lay beyond it, and the edge becomes the x axis.
    let edge = x[body.pins.indices()[0]].x;
    assert!(body.pins.indices().iter().all(|&p| x[p].x == edge));
    assert!(x.iter().all(|p| p.x >= edge));
    let hung = x
        .iter()
        .map(|p| [p.z, p.y - (p.x - edge), 0.0].map(Finite::of))
        .collect();
    body.positions = Some(hung);
    spec.simulation.air = Some(AirSpec {
        density: Positive::of(RHO),
        wind: [0.0, 0.0, wind_z].map(Finite::of),
        gust: None,
    });
    spec.build(&root()).unwrap()
}

#[test]
fn a_hanging_cloth_in_a_side_wind_moves_downwind_and_mirrors_when_reversed() {
    let settle = |wind: f64| {
        let mut scene = hanging_in_wind(wind);
        scene.simulation.advance(12_000).unwrap(); // 3 s
        scene.simulation.particles().centroid()
    };
    let (calm, east, west) = (settle(0.0), settle(4.0), settle(-4.0));
    eprintln!("centroid: calm {calm:?}, wind +z {east:?}, wind -z {west:?}");
    assert_eq!(calm.z, 0.0, "without wind nothing leaves the plane");
    assert!(east.z > 0.05, "a 4 m/s wind moved the cloth {} m", east.z);
    // z → -z maps one run onto the other exactly: same operations, mirrored signs.
    assert_eq!(west.z, -east.z);
    assert_eq!((west.x, west.y), (east.x, east.y));
    // Blown out of the vertical, the cloth's centre rises.
    assert!(east.y > calm.y);
}

#[test]
fn bad_air_is_refused_with_its_line_and_key() {
    let flag = hooke_scene::to_toml(&hooke_scene::builtin::builtin("flag").unwrap());
    let bad = flag.replace("density = 1.225", "density = -1.0");
    let e = hooke_scene::parse_scene(&bad, "flag.toml")
        .unwrap_err()
        .to_string();
    let line = bad.lines().position(|l| l.starts_with("density")).unwrap() + 1;
    assert!(
        e.contains(&format!("flag.toml: line {line}, column 11")),
        "{e}"
    );
    assert!(e.contains("expected a finite number > 0, found -1"), "{e}");
    let unknown = flag.replace("period = 1.7", "period = 1.7\nphase = 0.5");
    let e = hooke_scene::parse_scene(&unknown, "flag.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("phase"), "{e}");
    // Air acts on surfaces; a chain has none to give it.
    let mut chain = hooke_scene::builtin::builtin("chain").unwrap();
    chain.bodies[0].aero = Some(Default::default());
    let e = chain.build(&root()).unwrap_err().to_string();
    assert!(
        e.contains(".aero") && e.contains("only bodies with a surface"),
        "{e}"
    );
}
