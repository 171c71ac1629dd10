//! Collision responses and colliders: restitution apex heights, the analytic cylinder against
//! the OBJ table, the cloth staying on the table, and swapping the table mesh.

use crate::common::{builtin, root};
use hooke_collide::table::round;
use hooke_collide::{BoxInterior, Cylinder, Placement, Plane};
use hooke_core::{
    Collider, ColliderSlot, Integrator, Model, Particles, Response, Simulation, Vec3,
};
use hooke_scene::Overrides;

#[test]
fn restitution_apex_heights_fall_as_cr_to_the_2n() {
    let (h0, cr) = (1.0, 0.8);
    let mut p = Particles::default();
    p.push(Vec3::new(0.0, h0, 0.0), Vec3::zeros(), 1.0);
    let ground = ColliderSlot {
        shape: Box::new(Plane::ground(0.0)),
        response: Response::Restitution { cr, friction: 0.0 },
    };
    let model = Model {
        gravity: Vec3::new(0.0, -9.81, 0.0),
        colliders: vec![ground],
        ..Model::default()
    };
    let mut sim = Simulation::new(p, model, Integrator::Symplectic, 1e-5);
    let mut apexes = Vec::new();
    let mut last_vy = 0.0;
    while apexes.len() < 4 {
        sim.step().unwrap();
        let vy = sim.particles().v[0].y;
        if last_vy > 0.0 && vy <= 0.0 {
            apexes.push(sim.particles().x[0].y);
        }
        last_vy = vy;
    }
    for (n, apex) in apexes.iter().enumerate() {
        let expected = cr.powi(2 * (n as i32 + 1)) * h0;
        // An impact lands between steps: the speed is off by up to g dt, the height by
        // about 2 v g dt / g, 1e-4 m here.
        assert!(
            (apex - expected).abs() < 2e-4,
            "apex {}: {apex}, expected {expected}",
            n + 1
        );
    }
}

fn round_table() -> hooke_collide::TriMeshCollider {
    hooke_collide::load_mesh(
        &root().join("assets/meshes/table.obj"),
        &Placement::default(),
    )
    .unwrap()
}

fn analytic_top() -> Cylinder {
    Cylinder {
        center: Vec3::new(0.0, round::TOP_Y, 0.0),
        radius: round::TOP_RADIUS,
        thickness: round::TOP_THICKNESS,
    }
}

/// The rim of the 64-gon lies inside the circle by up to `R (1 - cos(π/64))`.
fn tessellation_error() -> f64 {
    round::TOP_RADIUS * (1.0 - (std::f64::consts::PI / round::SEGMENTS as f64).cos()) + 1e-6
}

#[test]
fn the_obj_table_agrees_with_the_analytic_cylinder() {
    let (mesh, cylinder) = (round_table(), analytic_top());
    let tol = tessellation_error();
    let (mut compared, mut inside) = (0, 0);
    for i in 0..=60 {
        for j in 0..=60 {
            for k in 0..=30 {
                let p = Vec3::new(
                    -0.7 + 1.4 * i as f64 / 60.0,
                    0.93 + 0.1 * k as f64 / 30.0,
                    -0.7 + 1.4 * j as f64 / 60.0,
                );
                let r = (p.x * p.x + p.z * p.z).sqrt();
                // Probes within the tessellation error of the rim, or on a face, may differ.
                let near_rim = (r - round::TOP_RADIUS).abs() < tol;
                let near_face = (p.y - round::TOP_Y).abs() < 1e-9
                    || (p.y - (round::TOP_Y - round::TOP_THICKNESS)).abs() < 1e-9;
                // The pedestal below the top is in the mesh only.
                if near_rim
                    || near_face
                    || p.y < round::TOP_Y - round::TOP_THICKNESS
                        && r < round::PEDESTAL_RADIUS + 1e-3
                {
                    continue;
                }
                compared += 1;
                assert_eq!(
                    mesh.inside(&p),
                    cylinder.inside(&p),
                    "contact decision differs at {p}"
                );
                if cylinder.inside(&p) {
                    inside += 1;
                    let (dm, dc) = (mesh.depth(&p), cylinder.depth(&p));
                    assert!(
                        (dm - dc).abs() <= tol,
                        "depth differs at {p}: mesh {dm}, cylinder {dc}"
                    );
                }
            }
        }
    }
    assert!(
        compared > 100_000 && inside > 10_000,
        "compared {compared}, inside {inside}"
    );
}

#[test]
fn no_cloth_particle_ends_up_inside_the_table_top() {
    let mut scene = builtin("cloth-table", &Overrides::default());
    let top = analytic_top();
    // Resting particles lie a contact thickness above the top (those wrapping the rim up to
    // a millimetre more).
    let rest = round::TOP_Y + scene.bodies[0].thickness;
    let mut on_top = 0;
    for frame in 0..scene.steps / scene.every {
        scene.simulation.advance(scene.every).unwrap();
        for x in &scene.simulation.particles().x {
            let r = (x.x * x.x + x.z * x.z).sqrt();
            // Inside the radius (less the tessellation error) and within the slab: inside.
            if r < top.radius - tessellation_error() {
                assert!(
                    top.depth(x) < 1e-9,
                    "frame {frame}: particle at {x} is {} m inside the top",
                    top.depth(x)
                );
            }
        }
        on_top = scene
            .simulation
            .particles()
            .x
            .iter()
            .filter(|x| (x.y - rest).abs() < 1e-3)
            .count();
    }
    // The middle of the cloth lies on the top: about π R² / h² = 420 particles.
    assert!(on_top > 250, "only {on_top} particles rest on the top");
    let lowest = crate::common::lowest(&scene);
    assert!(
        lowest < round::TOP_Y - 0.3,
        "the edges should hang down; lowest particle at {lowest}"
    );
}

#[test]
fn the_analytic_cylinder_table_gives_the_same_drape() {
    let run = |table: Option<&str>| {
        let mut scene = builtin(
            "cloth-table",
            &Overrides {
                table: table.map(|t| t.parse().unwrap()),
                duration: Some(1.5),
                ..Overrides::default()
            },
        );
        scene.simulation.advance(scene.steps).unwrap();
        scene.simulation.particles().x.clone()
    };
    let (mesh, cylinder) = (run(None), run(Some("cylinder")));
    let rest = round::TOP_Y + hooke_core::DEFAULT_CLOTH_THICKNESS;
    // Within a millimetre: near the rim the cloth wraps the edge and lifts a little.
    let stuck = |x: &[Vec3]| x.iter().filter(|p| (p.y - rest).abs() < 1e-3).count();
    let (a, b) = (stuck(&mesh), stuck(&cylinder));
    assert!(a > 250, "only {a} particles rest on the mesh top");
    // The mesh's rim is a 64-gon up to 0.72 mm inside the circle, and the cloth wraps a
    // polygon's edges where it wraps the circle: the ring of particles at the rim may differ
    // by a few percent (measured: 277 against 268).
    assert!(
        a.abs_diff(b) <= a / 25,
        "particles on the top: mesh {a}, cylinder {b}"
    );
}

#[test]
fn cloth_table_runs_on_a_swapped_square_table() {
    let path = root().join("assets/meshes/square-table.obj");
    let mut scene = builtin(
        "cloth-table",
        &Overrides {
            table: Some(hooke_scene::TableOverride::Mesh(path.display().to_string())),
            duration: Some(1.5),
            ..Overrides::default()
        },
    );
    scene.simulation.advance(scene.steps).unwrap();
    let top = hooke_collide::table::square::TOP_Y;
    let half = hooke_collide::table::square::HALF_SIDE;
    let h = scene.bodies[0].thickness;
    let x = &scene.simulation.particles().x;
    let on_top = x
        .iter()
        .filter(|p| (p.y - (top + h)).abs() < 1e-6 && p.x.abs() < half && p.z.abs() < half)
        .count();
    // A 1 m square top holds 400 particles of the cloth; sticking stops them sliding, so the
    // cloth landing last buckles into folds about 2 cm high and 184 touch the top.
    assert!(
        on_top > 150,
        "only {on_top} particles rest on the square top"
    );
    let at_round_height = x
        .iter()
        .filter(|p| (p.y - (round::TOP_Y + h)).abs() < 1e-6)
        .count();
    assert_eq!(
        at_round_height, 0,
        "particles rest at the old round table's height"
    );
    let inside = x
        .iter()
        .filter(|p| {
            p.x.abs() < half - 1e-3
                && p.z.abs() < half - 1e-3
                && p.y < top - 1e-6
                && p.y > top - 0.04
        })
        .count();
    assert_eq!(inside, 0, "particles inside the square top");
}

/// Implicit Euler at 20× the largest stable symplectic step still drapes the cloth over the
/// table: particles held by the stick response are filtered out of the solve, so long steps
/// cannot drag them through the 4 cm top.
#[test]
fn implicit_cloth_stays_on_the_table_at_twenty_times_the_symplectic_step() {
    let scene = crate::common::builtin("cloth-table", &hooke_scene::Overrides::default());
    let dt = 20.0
        * scene
            .simulation
            .stability()
            .max_dt(hooke_core::Integrator::Symplectic);
    let mut scene = crate::common::builtin(
        "cloth-table",
        &hooke_scene::Overrides {
            integrator: Some(hooke_core::Integrator::Implicit),
            dt: Some(dt),
            duration: Some(3.0),
            ..hooke_scene::Overrides::default()
        },
    );
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    let x = &scene.simulation.particles().x;
    let on_top = x
        .iter()
        .filter(|p| (p.x * p.x + p.z * p.z).sqrt() < 0.6 && (1.004..1.015).contains(&p.y))
        .count();
    assert!(on_top > 200, "only {on_top} particles rest on the top");
    let inside = x
        .iter()
        .filter(|p| (p.x * p.x + p.z * p.z).sqrt() < 0.59 && (0.961..0.999).contains(&p.y))
        .count();
    assert_eq!(inside, 0, "particles inside the tabletop");
    let lowest = crate::common::lowest(&scene);
    assert!(
        lowest > 0.3,
        "the edges hang, they do not fall: lowest y = {lowest}"
    );
}

/// `may_touch` is a promise the force loop relies on to skip colliders: wherever a plane or
/// the box says a box of particles cannot touch it, no point of that box (its corners and
/// random points inside) has a contact at that margin or any smaller one. Boxes are
/// random, from far clear to straddling a wall; the promise must be made for many of them
/// (or skipping would save nothing) and refused for every box holding a touching point.
#[test]
fn a_collider_that_says_a_box_is_clear_has_no_contact_in_it() {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let centre = Vec3::new(0.1, 0.2, 0.3);
    let shapes: Vec<Box<dyn Collider>> = vec![
        Box::new(Plane::ground(-1.0)),
        Box::new(Plane::inclined([1.0, 2.0, -1.5, 0.7], &centre).unwrap()),
        Box::new(Plane::inclined([-1.0, -2.0, 1.5, -0.7], &centre).unwrap()),
        Box::new(Plane::inclined([0.0, 0.0, 3.0, 1.0], &centre).unwrap()),
        Box::new(BoxInterior::jello()),
        Box::new(BoxInterior {
            min: Vec3::new(-2.5, -1.0, -2.0),
            max: Vec3::new(2.0, 2.5, 2.75),
        }),
    ];
    for shape in &shapes {
        let (mut clear, mut touching) = (0, 0);
        for _ in 0..4000 {
            let lo = Vec3::new(next(), next(), next()) * 6.0 - Vec3::repeat(3.0);
            let hi = lo + Vec3::new(next(), next(), next()) * next();
            let margin = [0.0, 0.01, 0.2][(next() * 3.0) as usize];
            let corners = (0..8).map(|k| {
                Vec3::new(
                    if k & 4 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 1 == 0 { lo.z } else { hi.z },
                )
            });
            let inside =
                (0..24).map(|_| lo + (hi - lo).component_mul(&Vec3::new(next(), next(), next())));
            let mut touches = false;
            for p in corners.chain(inside) {
                for m in [0.0, 0.5 * margin, margin] {
                    shape.contacts_within(&p, m, &mut |_| touches = true);
                }
            }
            if shape.may_touch(&lo, &hi, margin) {
                touching += usize::from(touches);
            } else {
                assert!(
                    !touches,
                    "{shape:?} promised {lo:?}..{hi:?} clear at {margin}"
                );
                clear += 1;
            }
        }
        assert!(
            clear > 400 && touching > 400,
            "{shape:?}: {clear} clear, {touching} touching"
        );
        let nan = Vec3::new(f64::NAN, 0.0, 0.0);
        assert!(
            shape.may_touch(&nan, &nan, 0.0),
            "{shape:?} promised a NaN box clear"
        );
    }
}
