//! Bit-identical results whatever the thread count: forces are reduced in an order fixed by
//! the problem, contacts are resolved per particle, pixels are written once per tile.

use crate::common::{builtin, with_integrator};
use hooke_core::{Integrator, Kernel, Vec3};
use hooke_scene::{Overrides, Scene};

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// The five public jello worlds (512 particles, penalty walls, force fields): each force
/// evaluation is one parallel pass whose threads share the particles as they finish them
/// (`assembly/small.rs`), and walls are asked about a group of particles only when they
/// may touch it. After 1000 steps, which take four of the five jellies into a wall, the
/// states are the same bits on one to four threads.
#[test]
fn jello_worlds_are_bit_identical_on_one_to_four_threads() {
    let mut walled = Vec::new();
    for name in crate::worlds::WORLDS {
        let run = |threads| {
            on_threads(threads, || {
                let spec = crate::worlds::world(name).to_scene(name).unwrap();
                let mut scene = spec.build(std::path::Path::new(".")).unwrap();
                let mut deepest = 0.0_f64;
                for _ in 0..100 {
                    scene.simulation.advance(10).unwrap();
                    let sim = &scene.simulation;
                    deepest = deepest.max(sim.model().max_penetration(&sim.particles().x));
                }
                (state(&scene), deepest)
            })
        };
        let (one, deepest) = run(1);
        if deepest > 0.0 {
            walled.push(name);
        }
        for threads in 2..=4 {
            assert_eq!(run(threads).0, one, "{name}: 1 vs {threads} threads");
        }
    }
    assert_eq!(walled, ["jello", "gravity", "moveLeft", "rotate"]);
}

fn state(scene: &Scene) -> Vec<(Vec3, Vec3)> {
    let p = scene.simulation.particles();
    p.x.iter().copied().zip(p.v.iter().copied()).collect()
}

/// The cloth workload at N = 100 has 58k springs in four partitions and 10k particles in
/// three reduction blocks, so every parallel path of the solver runs.
#[test]
fn cloth_workload_is_bit_identical_on_one_two_and_three_threads() {
    for integrator in Integrator::ALL {
        let run = |threads| {
            on_threads(threads, || {
                let spec = with_integrator(hooke_scene::workload::cloth(100), integrator);
                let mut scene = spec.build(std::path::Path::new(".")).unwrap();
                scene.simulation.advance(50).unwrap();
                state(&scene)
            })
        };
        let one = run(1);
        assert!(
            one.iter()
                .all(|(x, v)| x.iter().chain(v.iter()).all(|c| c.is_finite()))
        );
        // It moved: the pins hold, the rest falls.
        assert!(one[5050].0.y < 1.0);
        assert_eq!(one, run(2), "{integrator}: 1 vs 2 threads");
        assert_eq!(one, run(3), "{integrator}: 1 vs 3 threads");
    }
}

/// The same workload in a gusting wind: 19.6k triangles' air forces, computed in parallel
/// blocks and summed per particle in a fixed order, give the same bits on any thread count
/// with every integrator (each Runge–Kutta stage at its own time).
#[test]
fn air_forces_are_bit_identical_on_one_two_and_three_threads() {
    use hooke_scene::spec::{AirSpec, Finite, GustSpec, Positive};
    for integrator in Integrator::ALL {
        let run = |threads| {
            on_threads(threads, || {
                let mut spec = with_integrator(hooke_scene::workload::cloth(100), integrator);
                spec.simulation.air = Some(AirSpec {
                    density: Positive::of(1.225),
                    wind: [3.0, 0.0, 1.0].map(Finite::of),
                    gust: Some(GustSpec {
                        amplitude: [0.0, 0.0, 2.0].map(Finite::of),
                        period: Positive::of(1e-4),
                    }),
                });
                let mut scene = spec.build(std::path::Path::new(".")).unwrap();
                scene.simulation.advance(50).unwrap();
                state(&scene)
            })
        };
        let one = run(1);
        // The wind pushed the free corner along x and z (with block descent and Newton,
        // whose cloth falls flat there in these 0.5 ms, the cloth near its pins).
        let pushed = |(_, v): &(Vec3, Vec3)| v.x > 0.0 && v.z != 0.0;
        if integrator.solves_contacts() {
            assert!(one.iter().any(pushed), "{integrator}");
        } else {
            assert!(pushed(&one[9999]), "{integrator}: {:?}", one[9999]);
        }
        assert_eq!(one, run(2), "{integrator}: 1 vs 2 threads");
        assert_eq!(one, run(3), "{integrator}: 1 vs 3 threads");
    }
}

/// Cloth on the mesh table: sticking contacts are resolved in parallel blocks.
#[test]
fn cloth_table_contacts_are_bit_identical_on_one_and_two_threads() {
    let run = |threads| {
        on_threads(threads, || {
            let mut scene = builtin("cloth-table", &Overrides::default());
            // 0.5 s: the cloth has landed on the top and started to drape.
            scene.simulation.advance(2000).unwrap();
            state(&scene)
        })
    };
    assert_eq!(run(1), run(2));
}

/// A cloth folding onto itself: self-collision candidates, proximities and their
/// Gauss–Seidel projections run in one fixed order, whatever the thread count.
#[test]
fn cloth_pile_self_contacts_are_bit_identical_on_one_two_and_three_threads() {
    let run = |threads| {
        on_threads(threads, || {
            let mut scene = builtin("cloth-pile", &Overrides::default());
            // 1.5 s: the cloth has buckled and its folds touch (with Coulomb friction on the
            // ground its foot slides as it falls, so they touch later than at 0.75 s).
            scene.simulation.advance(6000).unwrap();
            assert!(scene.simulation.contact_stats().proximities > 0);
            state(&scene)
        })
    };
    let one = run(1);
    assert_eq!(one, run(2), "1 vs 2 threads");
    assert_eq!(one, run(3), "1 vs 3 threads");
}

/// Block descent at a frame per step on a cloth folding onto itself: colours, detections,
/// bounds and the Chebyshev steps depend on the scene alone, so any thread count gives the
/// same bits.
#[test]
fn block_descent_is_bit_identical_on_one_two_and_three_threads() {
    let run = |threads| {
        on_threads(threads, || {
            let overrides = Overrides {
                integrator: Some(Integrator::Vbd),
                dt: Some(1.0 / 60.0),
                ..Overrides::default()
            };
            let mut scene = builtin("cloth-pile", &overrides);
            // 1 s: the cloth has buckled and its folds touch.
            scene.simulation.advance(60).unwrap();
            state(&scene)
        })
    };
    let one = run(1);
    assert_eq!(one, run(2), "1 vs 2 threads");
    assert_eq!(one, run(3), "1 vs 3 threads");
}

/// The force loop's compilations for wider vector units (AVX2, AVX-512) give the portable
/// build's bits: on the cloth workload and on the cloth-table scene, whose springs have
/// several stiffnesses. Only the kernels this CPU runs are compared.
#[test]
fn every_force_kernel_gives_the_same_trajectory() {
    let run = |kernel: Kernel| {
        let spec = with_integrator(hooke_scene::workload::cloth(100), Integrator::Rk4);
        let mut cloth = spec.build(std::path::Path::new(".")).unwrap();
        cloth.simulation.set_kernel(kernel).unwrap();
        cloth.simulation.advance(50).unwrap();
        let mut table = builtin("cloth-table", &Overrides::default());
        table.simulation.set_kernel(kernel).unwrap();
        table.simulation.advance(1000).unwrap();
        (state(&cloth), state(&table))
    };
    let portable = run(Kernel::Portable);
    for kernel in Kernel::available() {
        assert!(run(kernel) == portable, "{kernel} differs from portable");
    }
}

/// Block descent's sweep sums each colour's springs eight particles at a time in the
/// chosen kernel's registers (AVX2, AVX-512), and one at a time in the portable build: the
/// same bits. On cloth-pile under `vbd` at 60 Hz (self-contact, recolouring at detections,
/// drag) and on the flag (wind), every kernel this CPU runs is compared with the portable one.
#[test]
fn every_kernel_gives_block_descent_the_same_trajectory() {
    let run = |name: &str, kernel: Kernel| {
        let overrides = Overrides {
            integrator: Some(Integrator::Vbd),
            dt: Some(1.0 / 60.0),
            ..Overrides::default()
        };
        let mut scene = builtin(name, &overrides);
        scene.simulation.set_kernel(kernel).unwrap();
        scene.simulation.advance(45).unwrap();
        state(&scene)
    };
    for name in ["cloth-pile", "flag"] {
        let portable = run(name, Kernel::Portable);
        for kernel in Kernel::available() {
            assert!(
                run(name, kernel) == portable,
                "{name}: {kernel} differs from portable"
            );
        }
    }
}

/// Symplectic Euler checks each block of particles for divergence as it updates it,
/// instead of a separate scan: the first bad step must still be the one reported. At 40×
/// the stable step the workload blows up within some steps; the state one step before
/// the reported one is sane, and the reported particle is the first bad one. The step
/// updates the state in place and, without a contact phase, keeps no start positions: the
/// report recovers them as `x - v dt`, and its step-size estimate, made from them, must
/// still be the one at the actual start.
#[test]
fn symplectic_reports_the_first_diverged_step_and_particle() {
    let spec = || {
        let mut spec = with_integrator(hooke_scene::workload::cloth(90), Integrator::Symplectic);
        Overrides {
            dt: Some(4e-4),
            ..Overrides::default()
        }
        .apply(&mut spec)
        .unwrap();
        spec.build(std::path::Path::new(".")).unwrap()
    };
    let mut scene = spec();
    let err = scene.simulation.advance(10_000).unwrap_err();
    assert!(err.step > 1, "diverged at once: {err}");
    let mut before = spec();
    before.simulation.advance(err.step - 1).unwrap();
    let sane = |x: &Vec3, v: &Vec3| {
        x.iter().all(|c| c.abs() <= hooke_core::SANE_BOUND) && v.iter().all(|c| c.is_finite())
    };
    let p = before.simulation.particles();
    assert!(p.x.iter().zip(&p.v).all(|(x, v)| sane(x, v)));
    let after = scene.simulation.particles();
    let first_bad = (0..after.len()).find(|&i| !sane(&after.x[i], &after.v[i]));
    assert_eq!(first_bad, Some(err.particle));
    assert!(
        scene.simulation.start_positions().is_none(),
        "no contact phase, no start positions"
    );
    // The estimate at the step's start, made from the recovered positions, is the one at
    // the actual start.
    let here = before.simulation.stability().max_dt(Integrator::Symplectic);
    assert!(
        (err.step_stable_dt / here - 1.0).abs() < 1e-6,
        "estimate at the step's start {:e} s, from the recovered start {:e} s",
        here,
        err.step_stable_dt
    );
    // The advice is half the run's start estimate (what `hooke check` says) or half the
    // step, the smaller: the state the diverging step started from has often run away.
    let limit = spec()
        .simulation
        .stability()
        .max_dt(Integrator::Symplectic)
        .min(scene.simulation.dt());
    let relative = (err.suggested_dt / (0.5 * limit) - 1.0).abs();
    assert!(
        relative < 1e-6,
        "suggested {:e} s, estimate at the start {:e} s",
        err.suggested_dt,
        limit
    );
}

/// A cloth whose particles arrive numbered at random is the same physics: its centre
/// particle after 100 steps lies within 1e-12 m of the ordered cloth's, with the same bits
/// on one, two and three threads, whether the numbering is kept or renumbered for
/// locality; and renumbering a shuffled grid recovers its row-by-row numbering exactly.
#[test]
fn a_shuffled_cloth_is_the_same_physics_on_any_thread_count() {
    use hooke_core::Renumbering;
    let n = 100;
    let centre = hooke_scene::workload::centre(n);
    let build = || {
        let spec = with_integrator(hooke_scene::workload::cloth(n), Integrator::Symplectic);
        spec.build(std::path::Path::new(".")).unwrap()
    };
    let ordered = {
        let mut scene = build();
        scene.simulation.advance(100).unwrap();
        scene.simulation.particles().x[centre]
    };
    for renumber in [false, true] {
        let run = |threads| {
            on_threads(threads, || {
                let mut scene = build();
                let sim = &mut scene.simulation;
                let shuffled = Renumbering::shuffled(n * n, &sim.bodies(), 7);
                sim.renumber(&shuffled).unwrap();
                let mut at = shuffled.new_index(centre);
                if renumber {
                    let local = sim.renumber_for_locality();
                    // Back to the generator's numbering, every particle.
                    let both = shuffled.then(&local);
                    assert_eq!(both, Renumbering::identity(n * n));
                    at = local.new_index(at);
                }
                sim.advance(100).unwrap();
                (state(&scene), at)
            })
        };
        let (one, at) = run(1);
        let y = one[at].0;
        assert!(
            (y - ordered).norm() <= 1e-12,
            "renumbered {renumber}: centre at {y}, ordered {ordered}"
        );
        assert!(y.y < 1.0, "it fell");
        assert_eq!(run(2).0, one, "renumbered {renumber}: 1 vs 2 threads");
        assert_eq!(run(3).0, one, "renumbered {renumber}: 1 vs 3 threads");
    }
}
