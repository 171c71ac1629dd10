//! The `single-spring` scene against the closed-form damped harmonic oscillator, and the
//! convergence order of every integrator measured by halving `dt`.

use crate::common::builtin;
use hooke_core::Integrator;
use hooke_scene::Overrides;
use hooke_scene::builtin::{SINGLE_SPRING_KD, SINGLE_SPRING_KS};

const G: f64 = 9.81;
const MASS: f64 = 1.0;
const ANCHOR_Y: f64 = 2.0;
const REST: f64 = 1.0;
const START_Y: f64 = 0.5;

/// Height of the mass at time `t`: `u(t) = e^{-ζω t}(u0 cos ω_d t + ζω u0/ω_d sin ω_d t)`
/// about the equilibrium `ANCHOR_Y - REST - m g / k`.
fn exact_y(t: f64) -> f64 {
    let (k, c, m) = (SINGLE_SPRING_KS, SINGLE_SPRING_KD, MASS);
    let equilibrium = ANCHOR_Y - REST - m * G / k;
    let u0 = START_Y - equilibrium;
    let w0 = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let wd = w0 * (1.0 - zeta * zeta).sqrt();
    let u = (-zeta * w0 * t).exp() * (u0 * (wd * t).cos() + zeta * w0 * u0 / wd * (wd * t).sin());
    equilibrium + u
}

fn error_at(integrator: Integrator, dt: f64, t_end: f64) -> f64 {
    let steps = (t_end / dt).round() as u64;
    let mut scene = builtin(
        "single-spring",
        &Overrides {
            integrator: Some(integrator),
            dt: Some(dt),
            steps: Some(steps),
            ..Overrides::default()
        },
    );
    scene.simulation.advance(steps).unwrap();
    let y = scene.simulation.particles().x[1].y;
    (y - exact_y(scene.simulation.time())).abs()
}

#[test]
fn single_spring_follows_the_damped_oscillator() {
    // The default scene (symplectic, dt = 1 ms) stays within 5 mm of the closed form over 5 s
    // of a 0.4 m swing: first order, ω dt = 0.01.
    let mut scene = builtin("single-spring", &Overrides::default());
    let mut worst: f64 = 0.0;
    for _ in 0..500 {
        scene.simulation.advance(10).unwrap();
        let y = scene.simulation.particles().x[1].y;
        worst = worst.max((y - exact_y(scene.simulation.time())).abs());
    }
    assert!(worst < 5e-3, "worst deviation {worst} m");
}

#[test]
fn single_spring_settles_at_rest_length_plus_mg_over_k() {
    let mut scene = builtin("single-spring", &Overrides::default());
    scene.simulation.advance(scene.steps).unwrap();
    let y = scene.simulation.particles().x[1].y;
    let expected = ANCHOR_Y - REST - MASS * G / SINGLE_SPRING_KS;
    assert!(
        (y - expected).abs() < 1e-4,
        "settled at {y}, expected {expected}"
    );
}

#[test]
fn each_integrator_converges_at_its_order() {
    // Error at t = 1 s for dt, dt/2, dt/4; the slope log2(e(dt)/e(dt/2)) must match the order.
    for (integrator, dt) in [
        (Integrator::Euler, 2e-3),
        (Integrator::Symplectic, 2e-3),
        (Integrator::Midpoint, 4e-3),
        (Integrator::Rk4, 2e-2),
        (Integrator::Implicit, 2e-3),
    ] {
        let errors: Vec<f64> = [1.0, 0.5, 0.25]
            .iter()
            .map(|s| error_at(integrator, dt * s, 1.0))
            .collect();
        for pair in errors.windows(2) {
            let slope = (pair[0] / pair[1]).log2();
            let order = integrator.order() as f64;
            assert!(
                (slope - order).abs() < 0.3,
                "{integrator}: errors {errors:?}, slope {slope}, expected {order}"
            );
        }
    }
}
