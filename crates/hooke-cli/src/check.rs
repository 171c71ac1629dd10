//! `hooke check`: the highest frequency of a scene and the largest stable step per
//! integrator, with what its step risks.

use crate::SetupArgs;
use crate::advice::{large_step_promises, newton_cost, recommend};
use crate::risks::{large_step_advice, thin_surfaces, tunnelling, warn_if_unstable};
use anyhow::Result;
use hooke::source;
use hooke_core::Integrator;
use hooke_core::Num;
use std::process::ExitCode;

pub fn check(arg: &str, setup: &SetupArgs) -> Result<ExitCode> {
    let scene = source::build(arg, &setup.overrides()?)?;
    let sim = &scene.simulation;
    let estimate = warn_if_unstable(&scene);
    println!(
        "scene {}: {} particles, {} springs",
        scene.spec.name,
        sim.particles().len(),
        sim.model().springs.len()
    );
    println!(
        "highest angular frequency ω_max ≈ {:.4e} rad/s (power iteration on M⁻¹K)",
        estimate.omega_max
    );
    println!(
        "fastest damping rate γ_max ≈ {:.4e} 1/s (springs' kd, drag, penalty dc, air; \
         an explicit step also needs dt γ_max within its real stability interval)",
        estimate.damping_max
    );
    println!(
        "scene step: dt = {} s with {}",
        Num(sim.dt()),
        sim.integrator()
    );
    for integrator in Integrator::ALL {
        let limit = estimate.max_dt(integrator);
        let mark = if integrator == sim.integrator() {
            "  <- scene"
        } else {
            ""
        };
        let line = match integrator {
            _ if !limit.is_finite() && integrator == Integrator::Vbd => {
                "stable for any dt once its steps are solved (accuracy still wants small steps)"
                    .to_string()
            }
            _ if !limit.is_finite() => {
                "stable for any dt (accuracy still wants small steps)".to_string()
            }
            // Their amplification factor exceeds 1 for every undamped mode at every dt.
            Integrator::Euler | Integrator::Midpoint => format!(
                "grows undamped oscillation at any dt; with enough damping, dt < {limit:.3e} s"
            ),
            _ => format!("stable for dt < {limit:.3e} s"),
        };
        println!("  {:<11} {line}{mark}", integrator.name());
    }
    let dt = sim.dt();
    let advice = recommend(&scene, &estimate, dt);
    println!(
        "recommended at dt = {} s: {} ({})",
        Num(dt),
        advice.integrator,
        advice.why
    );
    if let Some(advice) = large_step_advice(&scene, &estimate) {
        println!("{advice}");
    }
    // What the scene's integrator promises, and the recommended one's when it is another
    // large step.
    let mut promised = vec![sim.integrator()];
    if advice.integrator != sim.integrator() && advice.integrator.solves_contacts() {
        promised.push(advice.integrator);
    }
    for integrator in promised.into_iter().filter(|i| i.solves_contacts()) {
        if integrator == Integrator::Vbd {
            for (_, message) in crate::risks::volumetric_bodies(&scene) {
                println!("warning: {message}");
            }
        }
        if integrator == Integrator::Newton
            && let Some(cost) = newton_cost(&scene)
        {
            println!("warning: {cost}");
        }
        for line in large_step_promises(&scene, integrator) {
            println!("{line}");
        }
        let rule = sim.workspace().stop_rule_of(integrator);
        let update = if integrator == Integrator::Newton {
            "Newton step (before its line search)"
        } else {
            "iteration (and what the iterations' rate of contraction says is still to go)"
        };
        let stability = if integrator == Integrator::Vbd {
            ", and so stability: a step not solved to the end can gain energy (a 1 m cotton \
             sheet of 32 × 32 swinging down from its pinned edge did at the defaults), and a \
             run whose energy grows stops as diverged, saying how to solve its steps further"
        } else {
            ""
        };
        println!(
            "{} does not guarantee: a solved step{stability}. A step ends when its last {update} \
             moved no particle faster than {} m/s (--tolerance), or after {} iterations \
             (--iterations) whether or not it got there; a run says how many steps ended at \
             the budget, and `hooke bench scene` counts them and the final update's speed. \
             Contacts are inelastic (cr has no \
             effect), and a particle slides along a mesh or cylinder collider at most about \
             0.9 of its gap per detection (along the ground and planes freely), so fast \
             sliding over a tabletop at large steps is held back",
            integrator.name(),
            rule.tolerance,
            rule.iterations
        );
    }
    if sim.integrator().solves_contacts() {
        return Ok(ExitCode::SUCCESS);
    }
    if sim.integrator() == Integrator::Implicit {
        println!(
            "implicit guarantees: stability at any dt (one linearised Newton step per step, \
             conjugate gradients to 1e-8); not a solved nonlinear step, nor contacts inside \
             the solve: the contact phase after the step does as for the explicit schemes, \
             so a step that moves a particle farther than the tunnelling limits below can \
             leave a surface through a collider, itself or another surface (the run warns at \
             the first step that does)"
        );
    }
    // These concern the scene's own integrator, whose contacts come after its step; the
    // large steps keep the bounds stated above instead.
    let who = format!("{} (the scene's integrator)", sim.integrator().name());
    for t in tunnelling(&scene) {
        if t.risky() {
            println!(
                "warning: tunnelling under {who}: {}; keep dt below {:.3e} s",
                t.describe(dt),
                t.safe_dt
            );
        } else {
            println!(
                "thin collider under {who}: {}: no tunnelling below dt = {:.3e} s",
                t.describe(dt),
                t.safe_dt
            );
        }
    }
    for message in thin_surfaces(&scene) {
        println!("warning: tunnelling under {who}: {message}");
    }
    Ok(ExitCode::SUCCESS)
}
