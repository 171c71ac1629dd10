//! Newton's step (`integrator = "newton"`, docs/physics.md §4.2): implicit Euler solved to a
//! velocity tolerance at a display frame. The jello worlds, stiff lattices the block descent
//! cannot converge on at 60 Hz, keep their shape against RK4 at the worlds' own small step;
//! worlds changed in stiffness, mass and plane do too; no step takes its whole budget; and
//! the bits do not depend on the thread count. (The denim cantilever is in `material.rs`.)

use crate::common::builtin;
use hooke_core::{Integrator, Vec3};
use hooke_scene::world::World;
use hooke_scene::{Overrides, Scene};

/// The twelve edges of the 8×8×8 lattice's bounding cube, as corner index pairs
/// (`i*64 + j*8 + k`).
fn cube_edges() -> Vec<(usize, usize)> {
    let corner = |c: [usize; 3]| c[0] * 64 + c[1] * 8 + c[2];
    let mut edges = Vec::new();
    for a in 0..8usize {
        let ca = [7 * (a & 1), 7 * ((a >> 1) & 1), 7 * ((a >> 2) & 1)];
        for axis in 0..3 {
            if ca[axis] == 0 {
                let mut cb = ca;
                cb[axis] = 7;
                edges.push((corner(ca), corner(cb)));
            }
        }
    }
    edges
}

/// The shortest cube edge of the lattice now.
fn shortest_side(x: &[Vec3]) -> f64 {
    cube_edges()
        .iter()
        .map(|&(a, b)| (x[a] - x[b]).norm())
        .fold(f64::INFINITY, f64::min)
}

fn build(world: &World, name: &str, overrides: &Overrides) -> Scene {
    let mut spec = world.to_scene(name).unwrap();
    overrides.apply(&mut spec).unwrap();
    spec.build(std::path::Path::new(".")).unwrap()
}

/// The world run to its end: the shortest cube side over every step, and how many steps
/// took their whole iteration budget. Panics if the run stops (the energy watch).
fn shortest_over_run(world: &World, name: &str, overrides: &Overrides) -> (f64, usize) {
    let mut scene = build(world, name, overrides);
    let (mut shortest, mut capped) = (shortest_side(&scene.simulation.particles().x), 0);
    for n in 0..scene.steps {
        scene
            .simulation
            .step()
            .unwrap_or_else(|e| panic!("{name}: step {n}: {e}"));
        shortest = shortest.min(shortest_side(&scene.simulation.particles().x));
        capped += usize::from(scene.simulation.workspace().capped());
    }
    (shortest, capped)
}

fn at_60_hz() -> Overrides {
    on(Integrator::Newton)
}

fn on(integrator: Integrator) -> Overrides {
    Overrides {
        integrator: Some(integrator),
        dt: Some(1.0 / 60.0),
        ..Overrides::default()
    }
}

/// A jello world at a frame per step under Newton: never stopped, no step at its budget,
/// and no side of the cube below 0.8 of the shortest RK4 reaches at the world's own step.
fn keeps_its_shape(world: &World, name: &str) {
    keeps_its_shape_under(world, name, Integrator::Newton, None);
}

/// [`keeps_its_shape`] under `integrator` (block descent's budget is its own affair: its
/// capped steps are not counted), over `duration` seconds (the world's own run's when
/// `None`).
fn keeps_its_shape_under(world: &World, name: &str, integrator: Integrator, duration: Option<f64>) {
    let small = Overrides {
        duration,
        ..Overrides::default()
    };
    let (rk4, _) = shortest_over_run(world, name, &small);
    // Over the same simulated time as the small steps.
    let run = build(world, name, &small);
    let large = Overrides {
        duration: Some(run.steps as f64 * run.simulation.dt()),
        ..on(integrator)
    };
    let (large, capped) = shortest_over_run(world, name, &large);
    eprintln!("{name}: shortest side {large:.4} under {integrator} at 60 Hz, {rk4:.4} under RK4");
    assert!(
        capped == 0 || integrator != Integrator::Newton,
        "{name}: {capped} steps took their whole budget"
    );
    assert!(
        large >= 0.8 * rk4,
        "{name}: shortest side {large:.4} under {integrator} at 60 Hz, {rk4:.4} under RK4"
    );
}

/// The five public worlds. (Measured when this was written, shortest side Newton vs RK4:
/// jello 0.938 vs 0.791, moveLeft 0.969 vs 0.789, gravity 0.955 vs 0.905, rotate 0.957 vs
/// 0.867, skewedCorner 0.9997 vs 0.999; block descent flattened jello to 0.024.)
#[test]
fn the_jello_worlds_keep_their_shape_at_60_hz() {
    for name in crate::worlds::WORLDS {
        keeps_its_shape(&crate::worlds::world(name), name);
    }
}

/// Block descent too, since the penalty walls' damping is read at the step's start (read at
/// its iterate, the step's equations had no solution at a wall and block descent flattened
/// `jello.w` to 0.024 of its depth).
#[test]
fn the_jello_worlds_keep_their_shape_under_block_descent_at_60_hz() {
    for name in ["jello", "moveLeft", "rotate"] {
        keeps_its_shape_under(&crate::worlds::world(name), name, Integrator::Vbd, None);
    }
}

/// Worlds that are not among the public five, over 3 s (each meets a wall or the plane):
/// stiffer and softer springs, heavier points, stiffer walls, and a plane tilted the other
/// way.
#[test]
fn changed_jello_worlds_keep_their_shape_at_60_hz() {
    let long = Some(3.0);
    let mut stiff = crate::worlds::world("moveLeft");
    stiff.k_elastic *= 4.0;
    stiff.k_collision *= 4.0;
    keeps_its_shape_under(&stiff, "moveLeft stiffer", Integrator::Newton, long);
    let mut heavy = crate::worlds::world("rotate");
    heavy.k_elastic *= 0.5;
    heavy.mass *= 2.0;
    keeps_its_shape_under(
        &heavy,
        "rotate softer and heavier",
        Integrator::Newton,
        long,
    );
    let mut tilted = crate::worlds::world("gravity");
    tilted.plane = Some([-1.0, -1.0, 1.0, 4.0]);
    keeps_its_shape_under(
        &tilted,
        "gravity on another plane",
        Integrator::Newton,
        long,
    );
}

/// One Newton step is one global solve per iteration: its sums run in an order fixed by the
/// problem, so a jello world and the cloth on its table give the same bits on 1 and 2
/// threads.
#[test]
fn newton_is_bit_identical_on_one_and_two_threads() {
    let state = |scene: &Scene| {
        let p = scene.simulation.particles();
        p.x.iter()
            .zip(&p.v)
            .map(|(x, v)| (*x, *v))
            .collect::<Vec<_>>()
    };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut world = build(&crate::worlds::world("jello"), "jello", &at_60_hz());
                world.simulation.advance(60).unwrap();
                let mut cloth = builtin("cloth-table", &at_60_hz());
                cloth.simulation.advance(60).unwrap();
                (state(&world), state(&cloth))
            })
    };
    assert_eq!(run(1), run(2));
}

/// Newton's trial points are clipped to block descent's bounds: the cloth on its round table
/// at a frame per step has no crossing on any of its frames (checked by `contact.rs`'s
/// independent checker).
#[test]
fn newton_drapes_the_round_table_without_crossing() {
    let overrides = Overrides {
        every: Some(1),
        ..at_60_hz()
    };
    crate::contact::assert_no_crossings_with("cloth-table", &overrides, "newton");
}

/// A sleeve Blender made (`tests/fixtures/blender-sleeve.obj`: an open cylinder 12 cm
/// across, its 4:1 triangles from 11.8 to 51 mm), of silk, dropped 0.5 m onto the ground
/// under Newton at 1/60 s, lands on its own folds. Its total energy can only fall (implicit
/// Euler with inelastic contacts, nothing doing work). A line search that took its last
/// halving even when the energy rose, with bounds that moved particles whatever their
/// forces asked, took it from 0.074 J to 0.23 J four steps after landing, and the run
/// stopped as diverged. Now it falls, and the tube flattens to under half its diameter.
/// No two triangles cross on any frame (the independent checker, `contact.rs`), except
/// pairs the large steps skip (docs/physics.md §4.1): within four thicknesses of each
/// other at rest, here one 11.8 mm edge across the sleeve's ring, which its tight creases
/// fold through (up to 3 such pairs a step; block descent, up to 5 a frame; symplectic at
/// 1e-4 s, whose contacts skip only pairs within two thicknesses, none on 21 frames); the
/// run says so at each step one is (`creases::step_watching_folds`).
#[test]
fn a_blender_sleeve_lands_on_its_folds_under_newton_without_gaining_energy() {
    let mut scene = crate::creases::blender_sleeve("newton");
    scene.simulation.watch_energy(false);
    let energy = |scene: &Scene| crate::conservation::energy(&scene.simulation);
    let start = energy(&scene);
    let mut highest = start;
    let folds = crate::creases::step_watching_folds(&mut scene, |scene| {
        highest = highest.max(energy(scene));
    });
    assert!(
        highest <= start * (1.0 + 1e-3),
        "the energy rose from {start:.4e} J to {highest:.4e} J"
    );
    folds.assert_only_skipped_pairs_cross_and_are_said();
    assert!(
        folds.most <= 4,
        "{} skipped pairs crossed at one step",
        folds.most
    );
    let top = scene
        .simulation
        .particles()
        .x
        .iter()
        .map(|p| p.y)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        top < 0.06,
        "the sleeve's top stands {top:.3} m above the ground"
    );
}
