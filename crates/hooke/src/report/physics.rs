//! Closed forms the built-in physics must meet, with the contract's constants written
//! here: the single spring settles at `rest + m g / k`, and a sheet falling face-on in air
//! reaches `√(2 m g / (ρ C_d A))`.

use super::convergence::G;
use crate::Result;
use hooke_core::{
    AeroSurface, Air, Integrator, Model, Particles, Simulation, Spring, SpringKind, Vec3,
};
use hooke_scene::Overrides;
use hooke_scene::builtin::SINGLE_SPRING_KS;
use serde::Serialize;

/// Air at sea level, kg/m³.
pub const RHO: f64 = 1.225;

/// One measured quantity against its formula.
#[derive(Serialize)]
pub(crate) struct Closed {
    pub(crate) what: String,
    pub(crate) formula: String,
    pub(crate) expected: f64,
    pub(crate) measured: f64,
    /// The largest difference allowed, in the quantity's unit.
    pub(crate) tolerance: f64,
    pub(crate) unit: String,
}

impl Closed {
    pub(crate) fn passed(&self) -> bool {
        (self.measured - self.expected).abs() <= self.tolerance
    }
}

/// `single-spring` run to its end (20 s, its swing decayed below 0.1 mm): the mass hangs
/// `rest + m g / k` below the anchor.
fn spring_statics() -> Result<Closed> {
    let mut scene = crate::source::build("single-spring", &Overrides::default())?;
    let steps = scene.steps;
    crate::driver::advance(&mut scene, steps)?;
    let y = scene.simulation.particles().x[1].y;
    Ok(Closed {
        what: "single-spring: height at rest".into(),
        formula: "anchor − rest − m g / k".into(),
        expected: 2.0 - 1.0 - 1.0 * G / SINGLE_SPRING_KS,
        measured: y,
        tolerance: 2e-4,
        unit: "m".into(),
    })
}

/// A 9 × 9 sheet of 1 m² and 50 g falling face-on from rest for 2 s.
fn terminal_speed() -> Result<Closed> {
    let (n, side, mass) = (9usize, 1.0, 0.05);
    let (particles, model) = falling_sheet(
        n,
        side,
        mass,
        Vec3::new(0.0, 10.0, 0.0),
        (Vec3::x(), Vec3::z()),
    );
    let mut sim = Simulation::new(particles, model, Integrator::Symplectic, 1e-3);
    for _ in 0..2000 {
        crate::interrupt::check(&sim)?;
        sim.step()?;
    }
    let v = sim.particles().v.iter().map(|v| v.y).sum::<f64>() / (n * n) as f64;
    let expected = (2.0 * mass * G / (RHO * 1.0 * side * side)).sqrt();
    Ok(Closed {
        what: "air: a sheet falling face-on, speed after 2 s".into(),
        formula: "√(2 m g / (ρ C_d A))".into(),
        expected,
        measured: -v,
        tolerance: 0.01 * expected,
        unit: "m/s".into(),
    })
}

/// A square sheet in air (density [`RHO`], `C_d` 1, no lift, no wind) under gravity 9.81 m/s²: `n × n` particles and `side` metres, of `mass` kg in all, centred at
/// `centre` and spanned by the unit vectors `a` and `b`; each particle weighs its share of
/// the triangles' area (lumped masses), so air and gravity accelerate every particle alike
/// and the sheet stays flat. Stiff structural springs hold its shape.
pub fn falling_sheet(
    n: usize,
    side: f64,
    mass: f64,
    centre: Vec3,
    (a, b): (Vec3, Vec3),
) -> (Particles, Model) {
    let h = side / (n - 1) as f64;
    let id = |r: usize, c: usize| (r * n + c) as u32;
    let mut triangles = Vec::new();
    for r in 0..n - 1 {
        for c in 0..n - 1 {
            triangles.push([id(r, c), id(r + 1, c), id(r + 1, c + 1)]);
            triangles.push([id(r, c), id(r + 1, c + 1), id(r, c + 1)]);
        }
    }
    // Each triangle has area h²/2, a third of it to each corner.
    let mut share = vec![0.0; n * n];
    for t in &triangles {
        for &p in t {
            share[p as usize] += h * h / 6.0;
        }
    }
    let mut particles = Particles::default();
    for r in 0..n {
        for c in 0..n {
            let offset = a * (c as f64 * h - 0.5 * side) + b * (r as f64 * h - 0.5 * side);
            let m = mass * share[r * n + c] / (side * side);
            particles.push(centre + offset, Vec3::zeros(), m);
        }
    }
    let mut springs = Vec::new();
    for r in 0..n {
        for c in 0..n {
            for (dr, dc) in [(0, 1), (1, 0)] {
                if r + dr < n && c + dc < n {
                    springs.push(Spring {
                        i: id(r, c),
                        j: id(r + dr, c + dc),
                        rest: h,
                        ks: 500.0,
                        kd: 0.05,
                        kind: SpringKind::Structural,
                    });
                }
            }
        }
    }
    let model = Model {
        springs,
        gravity: Vec3::new(0.0, -G, 0.0),
        air: Some(Air {
            density: RHO,
            wind: Vec3::zeros(),
            gust: None,
        }),
        aero: vec![AeroSurface {
            triangles,
            drag: 1.0,
            lift: 0.0,
        }],
        ..Model::default()
    };
    (particles, model)
}

/// Both checks.
pub(crate) fn checks() -> Result<Vec<Closed>> {
    Ok(vec![spring_statics()?, terminal_speed()?])
}
