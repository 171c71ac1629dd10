//! Conservation laws: momentum without external forces, and what each integrator does to
//! energy (bounded for symplectic Euler, growing for explicit Euler, decaying for backward
//! Euler, which stays stable far beyond the explicit limit).

use hooke_core::{Integrator, Model, Particles, Simulation, Spring, SpringKind, Vec3};
use hooke_scene::SceneSpec;
use hooke_scene::spec::Finite;

fn momentum(p: &Particles) -> Vec3 {
    p.v.iter()
        .zip(&p.mass)
        .fold(Vec3::zeros(), |acc, (v, m)| acc + v * *m)
}

#[test]
fn a_free_spinning_jelly_conserves_momentum() {
    // The jello cube with gravity and the ground removed, thrown and spinning.
    let mut spec: SceneSpec = hooke_scene::builtin::builtin("jello-cube").unwrap();
    spec.simulation.gravity = [Finite::of(0.0); 3];
    spec.colliders.clear();
    // A drift plus a different velocity per particle, so the springs work hard inside it.
    spec.bodies[0].velocities = Some(
        (0..512)
            .map(|i| {
                let t = i as f64;
                [
                    Finite::of(1.0 + (t * 0.37).sin()),
                    Finite::of(2.0 + (t * 0.61).cos()),
                    Finite::of(-0.5 + (t * 0.23).sin()),
                ]
            })
            .collect(),
    );
    for integrator in Integrator::ALL {
        let s = crate::common::with_integrator(spec.clone(), integrator);
        let mut scene = s.build(std::path::Path::new(".")).unwrap();
        let p0 = momentum(scene.simulation.particles());
        scene.simulation.advance(2000).unwrap();
        let p1 = momentum(scene.simulation.particles());
        assert!(
            (p1 - p0).norm() < 1e-12,
            "{integrator}: momentum {p0} -> {p1}"
        );
    }
}

fn undamped_pair(integrator: Integrator) -> Simulation {
    let mut p = Particles::default();
    p.push(Vec3::new(0.0, 0.0, 0.0), Vec3::zeros(), 1.0);
    p.push(Vec3::new(1.5, 0.0, 0.0), Vec3::zeros(), 1.0);
    let spring = Spring {
        i: 0,
        j: 1,
        rest: 1.0,
        ks: 100.0,
        kd: 0.0,
        kind: SpringKind::Other,
    };
    Simulation::new(
        p,
        Model {
            springs: vec![spring],
            ..Model::default()
        },
        integrator,
        1e-2,
    )
}

/// A state's total energy: kinetic plus potential (springs, gravity, penalty springs).
pub(crate) fn energy(sim: &Simulation) -> f64 {
    let s = hooke_core::Summary::of(sim.model(), sim.particles());
    s.kinetic + s.potential
}

#[test]
fn symplectic_energy_stays_bounded_while_explicit_euler_grows() {
    let mut symplectic = undamped_pair(Integrator::Symplectic);
    let mut euler = undamped_pair(Integrator::Euler);
    // Its energy would stop the run as diverged (docs/physics.md §7) long before 10 s: here
    // the growth itself is watched.
    let mut watched = undamped_pair(Integrator::Euler);
    euler.watch_energy(false);
    let e0 = energy(&symplectic);
    let mut worst: f64 = 0.0;
    for _ in 0..100 {
        symplectic.advance(10).unwrap();
        euler.advance(10).unwrap();
        if watched.time() < 5.0 {
            let _ = watched.advance(10);
        }
        worst = worst.max((energy(&symplectic) - e0).abs() / e0);
    }
    // ω dt = 0.14: symplectic Euler's energy oscillates within O(ω dt) and never drifts.
    assert!(worst < 0.1, "symplectic energy drifted by {worst}");
    // Explicit Euler multiplies the energy by 1 + ω²dt² = 1.02 per step: ×4e8 over 10 s.
    assert!(
        energy(&euler) > 100.0 * e0,
        "explicit Euler energy {} from {e0}",
        energy(&euler)
    );
    // Watched, the run stopped once its energy passed ten times its start's scale.
    let e = watched.advance(1).unwrap_err();
    assert!(e.what.contains("the energy grew"), "{e}");
    assert!(energy(&watched) < 100.0 * e0, "{}", energy(&watched));
}

/// Backward Euler is stable at any step: at 20× the largest stable symplectic step the
/// hanging cloth still settles into its drape, and on an undamped spring the energy decays
/// instead of growing.
#[test]
fn implicit_euler_is_stable_at_twenty_times_the_symplectic_limit() {
    let scene = crate::common::builtin("hanging-cloth", &hooke_scene::Overrides::default());
    let limit = scene.simulation.stability().max_dt(Integrator::Symplectic);
    let dt = 20.0 * limit;
    let mut scene = crate::common::builtin(
        "hanging-cloth",
        &hooke_scene::Overrides {
            integrator: Some(Integrator::Implicit),
            dt: Some(dt),
            ..hooke_scene::Overrides::default()
        },
    );
    // 4 s of simulated time.
    let steps = (4.0 / dt).ceil() as u64;
    scene.simulation.advance(steps).unwrap();
    let s = hooke_core::Summary::of(scene.simulation.model(), scene.simulation.particles());
    assert!(s.max_speed < 0.5, "still moving fast: {}", s.max_speed);
    // Hangs from its pins at y = 2 with a sag, the free corners below.
    assert!(
        s.max.y <= 2.0 + 1e-9 && s.min.y > 0.8 && s.min.y < 1.1,
        "{s:?}"
    );

    let mut pair = undamped_pair(Integrator::Implicit);
    let e0 = energy(&pair);
    let mut previous = e0;
    for _ in 0..100 {
        pair.advance(10).unwrap();
        let e = energy(&pair);
        assert!(
            e <= previous * (1.0 + 1e-12),
            "energy grew: {previous} -> {e}"
        );
        previous = e;
    }
    assert!(
        previous < 0.9 * e0,
        "backward Euler damps: {e0} -> {previous}"
    );
}
