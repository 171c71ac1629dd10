//! A step asked to stop (`Simulation::set_cancel`, which the command line answers with
//! Ctrl-C) ends where it is: no solver iteration and no contact phase run once the question
//! answers yes, so one Ctrl-C ends a step of a million particles within a fraction of a
//! second. Asked and answered no, the same step runs in full.

use crate::common::builtin;
use hooke_core::Integrator;
use hooke_scene::Overrides;

fn stop() -> bool {
    true
}

fn go_on() -> bool {
    false
}

/// The built-in tablecloth (36², its contacts with the table and itself) after one step of
/// `integrator` at 1/60 s whose cancel question is `asked`: the solver's iterations (conjugate
/// gradients, or block descent's) and the contact phase's candidate-list builds.
fn one_step(integrator: Integrator, asked: fn() -> bool) -> (usize, usize) {
    let mut scene = builtin(
        "tablecloth",
        &Overrides {
            integrator: Some(integrator),
            dt: Some(1.0 / 60.0),
            ..Default::default()
        },
    );
    scene.simulation.set_cancel(asked);
    scene.simulation.advance(1).unwrap();
    let ws = scene.simulation.workspace();
    (
        ws.cg_iterations() + ws.vbd_iterations(),
        scene.simulation.contact_stats().rebuilds as usize,
    )
}

#[test]
fn a_step_asked_to_stop_ends_before_its_next_iteration() {
    for integrator in [Integrator::Implicit, Integrator::Vbd, Integrator::Newton] {
        let (iterations, _) = one_step(integrator, go_on);
        assert!(
            iterations > 0,
            "{integrator}: {iterations} iterations in full"
        );
        let (iterations, builds) = one_step(integrator, stop);
        assert_eq!(iterations, 0, "{integrator}: iterations after the stop");
        assert_eq!(builds, 0, "{integrator}: a contact phase after the stop");
    }
    // The implicit step's contact phase runs after it; asked to stop, it does not.
    let (_, builds) = one_step(Integrator::Implicit, go_on);
    assert!(
        builds > 0,
        "the implicit step's contact phase built no candidate list"
    );
}
