//! Bad starts are handled or refused (docs/physics.md §3.4 and §7): a body started inside a
//! collider is moved out before the first step, in every integrator, or refused when it
//! cannot be; bodies started through each other are warned about; a run whose energy grows
//! far beyond what anything supplied stops as diverged instead of grinding on; absurd
//! densities and penalty stiffnesses are refused with their key; `hooke check`'s estimate
//! counts the air and is the one a divergence names.

use crate::common::lowest;
use hooke_core::Integrator;
use hooke_scene::SceneSpec;

/// Sets `key` of `spec` to the TOML value `value`.
fn set(spec: &mut SceneSpec, key: &str, value: &str) {
    let table: toml::Table = toml::from_str(&format!("v = {value}")).unwrap();
    spec.set(key, table["v"].clone())
        .unwrap_or_else(|e| panic!("{key} = {value}: {e}"));
}

/// A 10×10 cloth of the cloth-table scene, its lowest corner at `origin`, run with
/// `integrator` for `duration` seconds.
fn small_cloth(origin: [f64; 3], integrator: Integrator, duration: f64) -> SceneSpec {
    let mut spec = hooke_scene::builtin::builtin("cloth-table").unwrap();
    let [x, y, z] = origin;
    set(
        &mut spec,
        "body.0.origin",
        &format!("[{x:?}, {y:?}, {z:?}]"),
    );
    set(&mut spec, "body.0.shape.size", "[10, 10]");
    set(&mut spec, "simulation.duration", &format!("{duration:?}"));
    crate::common::with_integrator(spec, integrator)
}

fn build(spec: &SceneSpec) -> Result<hooke_scene::Scene, hooke_scene::BuildError> {
    spec.build(&crate::common::root().join("assets/scenes"))
}

#[test]
fn a_cloth_started_under_the_ground_ends_above_it_in_every_integrator() {
    for depth in [0.01, 0.1] {
        for integrator in Integrator::ALL {
            // Away from the table, below the ground at y = 0.
            let spec = small_cloth([2.0, -depth, 0.0], integrator, 1.0);
            let mut scene = build(&spec).unwrap();
            let said = scene.warnings().join("\n");
            assert!(said.contains("moved out before the first step"), "{said}");
            let steps = scene.steps;
            scene.simulation.advance(steps).unwrap();
            let thickness = scene.bodies[0].thickness;
            let low = lowest(&scene);
            // Resting on the ground at its thickness (within a tenth of it), not launched.
            assert!(
                (low - thickness).abs() < 0.1 * thickness,
                "{integrator} from {depth} m under: lowest at {low} m"
            );
            let top = scene
                .simulation
                .particles()
                .x
                .iter()
                .map(|p| p.y)
                .fold(0.0, f64::max);
            assert!(top < 2.0 * thickness, "{integrator}: launched to {top} m");
        }
    }
}

#[test]
fn a_cloth_started_across_a_tabletop_is_refused_with_its_body_and_collider() {
    for integrator in Integrator::ALL {
        // Through the round table's top (at y = 1) and over its rim.
        let spec = small_cloth([-0.8, 0.98, -0.8], integrator, 1.0);
        let e = build(&spec).unwrap_err().to_string();
        assert!(
            e.contains("body[0] 'cloth'")
                && e.contains("collider[1]")
                && e.contains("start the body outside"),
            "{integrator}: {e}"
        );
    }
}

#[test]
fn a_cloth_started_inside_a_tabletop_that_it_can_leave_upwards_is_moved_onto_it() {
    // 10 × 5 cm spacing: a half-metre cloth wholly over the round top, 1 cm into it.
    let spec = small_cloth([-0.25, 0.99, -0.25], Integrator::Symplectic, 0.2);
    let mut scene = build(&spec).unwrap();
    let top = 1.0;
    let thickness = scene.bodies[0].thickness;
    assert!(
        lowest(&scene) >= top + thickness - 1e-9,
        "{}",
        lowest(&scene)
    );
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    assert!(lowest(&scene) > top, "{}", lowest(&scene));
}

#[test]
fn bodies_started_through_each_other_are_warned_about_and_a_stack_is_not() {
    let path = crate::common::root().join("assets/examples/cloth-stack.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let stack = hooke_scene::parse_scene(&text, &path).unwrap();
    let scene = stack.build(path.parent().unwrap()).unwrap();
    assert!(scene.warnings().is_empty(), "{:?}", scene.warnings());
    // The second cloth lowered into the first, tilted through it.
    let mut through = stack.clone();
    let first = toml::Value::try_from(&stack).unwrap()["body"][0]["origin"].clone();
    let [x, y, z] = [0, 1, 2].map(|k| first[k].as_float().unwrap());
    set(
        &mut through,
        "body.1.origin",
        &format!("[{x:?}, {:?}, {z:?}]", y + 0.01),
    );
    set(&mut through, "body.1.rotate", "[2.0, 0.0, 0.0]");
    let scene = through.build(path.parent().unwrap()).unwrap();
    let said = scene.warnings().join("\n");
    assert!(
        said.contains("'cloth-1' and 'cloth-2' start through each other"),
        "{said}"
    );
}

#[test]
fn energy_from_nowhere_stops_the_run_as_diverged_while_values_are_still_finite() {
    // Explicit Euler on the chain grows its energy at a step well inside the sanity bound.
    let mut spec = hooke_scene::builtin::builtin("chain").unwrap();
    spec = crate::common::with_integrator(spec, Integrator::Euler);
    set(&mut spec, "simulation.dt", "0.002");
    set(&mut spec, "simulation.duration", "60.0");
    let mut scene = build(&spec).unwrap();
    let steps = scene.steps;
    let e = scene.simulation.advance(steps).unwrap_err();
    let message = e.to_string();
    assert!(message.contains("the energy grew"), "{message}");
    let p = scene.simulation.particles();
    assert!(
        p.x.iter().all(|x| x.norm() < 1e3),
        "stopped before the state blew up"
    );
    // The built-in chain with its own integrator runs to its end with no such stop.
    let mut own = hooke_scene::builtin::builtin("chain").unwrap();
    set(&mut own, "simulation.duration", "60.0");
    let mut scene = build(&own).unwrap();
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
}

/// A step far beyond symplectic Euler's stable one blows the 128² tablecloth up in its own
/// plane: its triangles grow metres long and lie over one another. The contact phase finds
/// that more surface pairs lie within its reach than layers a thickness apart can hold and
/// stops the run as diverged there, instead of gathering them (before: 40 million pairs at
/// the fourth step, a 24 GB process killed by the system).
#[test]
fn a_step_that_crushes_a_cloth_through_itself_stops_as_diverged_at_its_contacts() {
    let path = crate::common::root().join("benches/scenes/tablecloth-128-drape.toml");
    let spec = hooke_scene::load_scene(&path).unwrap();
    let spec = crate::common::with_integrator(spec, Integrator::Symplectic);
    let mut scene = spec.build(path.parent().unwrap()).unwrap();
    let e = scene.simulation.advance(10).unwrap_err();
    assert!(e.step <= 5, "step {}", e.step);
    let message = e.to_string();
    assert!(message.contains("crushed or tore"), "{message}");
    assert!(message.contains("exceeds its stable estimate"), "{message}");
    // The state it stopped at holds that many pairs, counted without the contact phase: a
    // particle in every 64th lies within the reach (the thickness and the skin, three
    // thicknesses) of 3,562 of the cloth's triangles not its own on average, where the cap
    // allows 627 a particle (a pile of seven layers, the most the reach can hold, would
    // bring about 150).
    let sim = &scene.simulation;
    let (model, x) = (sim.model(), &sim.particles().x);
    let surface = &model.surfaces[0];
    let reach = 3.0 * surface.thickness;
    let near = |p: usize| {
        surface
            .triangles
            .iter()
            .filter(|t| !t.contains(&(p as u32)))
            .filter(|t| {
                let [a, b, c] = t.map(|i| x[i as usize]);
                let w = hooke_core::contact::proximity::point_triangle(&x[p], &a, &b, &c);
                (a * w[0] + b * w[1] + c * w[2] - x[p]).norm() < reach
            })
            .count()
    };
    let sampled: Vec<usize> = (0..x.len()).step_by(64).map(near).collect();
    let mean = sampled.iter().sum::<usize>() as f64 / sampled.len() as f64;
    assert!(
        mean > 1500.0,
        "{mean} triangles within the reach of a particle"
    );
    // Nothing like it on the way down: the same cloth at a step symplectic Euler takes holds
    // 7.8 candidate pairs of every kind a particle after 200 steps.
    let spec = hooke_scene::load_scene(&path).unwrap();
    let mut spec = crate::common::with_integrator(spec, Integrator::Symplectic);
    set(&mut spec, "simulation.dt", "1e-4");
    let mut scene = spec.build(path.parent().unwrap()).unwrap();
    scene.simulation.advance(200).unwrap();
    let candidates = scene.simulation.contact_stats().candidates;
    assert!(candidates < 16 * x.len(), "{candidates}");
}

#[test]
fn absurd_air_and_penalty_stiffness_are_refused_with_their_key() {
    let mut flag = hooke_scene::builtin::builtin("flag").unwrap();
    set(&mut flag, "simulation.air.density", "1e100");
    let e = build(&flag).unwrap_err().to_string();
    assert!(e.contains("simulation.air.density"), "{e}");
    for dt in ["1e-160", "1e160", "1e-16"] {
        let mut chain = hooke_scene::builtin::builtin("chain").unwrap();
        set(&mut chain, "simulation.dt", dt);
        let e = build(&chain).unwrap_err().to_string();
        assert!(
            e.contains("simulation.dt") && e.contains("represent"),
            "{dt}: {e}"
        );
    }
    // A course world: its box and plane are penalty colliders.
    let world = crate::common::root().join("assets/worlds/jello.w");
    let mut jelly = hooke_scene::world::load_world(&world)
        .unwrap()
        .to_scene("jello")
        .unwrap();
    let k = 0;
    set(&mut jelly, &format!("collider.{k}.response.kc"), "1e300");
    let e = build(&jelly).unwrap_err().to_string();
    assert!(e.contains(&format!("collider[{k}].response.kc")), "{e}");
}

#[test]
fn the_check_counts_the_air_and_a_divergence_names_the_checks_estimate() {
    let calm = build(&hooke_scene::builtin::builtin("flag").unwrap()).unwrap();
    let mut gale = hooke_scene::builtin::builtin("flag").unwrap();
    set(&mut gale, "simulation.air.wind", "[300.0, 0.0, 0.0]");
    set(
        &mut gale,
        "simulation.air.gust.amplitude",
        "[0.0, 0.0, 0.0]",
    );
    let mut gale = build(&gale).unwrap();
    let dt = |s: &hooke_scene::Scene| s.simulation.stability().max_dt(Integrator::Symplectic);
    // The gale's air is stiffer and more damping than the flag's springs.
    assert!(
        dt(&gale) < 0.5 * dt(&calm),
        "{} vs {}",
        dt(&gale),
        dt(&calm)
    );
    let checked = dt(&gale);
    let steps = gale.steps;
    let e = gale.simulation.advance(steps).unwrap_err();
    assert_eq!(e.stable_dt, checked, "{e}");
}
