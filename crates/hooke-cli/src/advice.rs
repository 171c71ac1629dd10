//! What `hooke check` recommends for a scene at a step, and what the recommended (or the
//! scene's) integrator promises, body by body: a promise names the bodies it covers, and
//! where no integrator keeps one, it says so.

use crate::risks::{layer_limit, tunnelling, volumetric_bodies};
use hooke_core::{Integrator, Num, StabilityEstimate};
use hooke_scene::{Scene, Topology};

/// The integrator `check` recommends at a step, and why.
pub(crate) struct Advice {
    pub(crate) integrator: Integrator,
    pub(crate) why: String,
}

/// The integrator to use for `scene` at step `dt`: an explicit one while its step is stable
/// and no collider or layer can be crossed in a step; otherwise the large step that suits
/// the bodies (Newton for lattices and stiff bodies, block descent for cloth, chains and
/// points).
pub(crate) fn recommend(scene: &Scene, estimate: &StabilityEstimate, dt: f64) -> Advice {
    let sim = &scene.simulation;
    let explicit = if sim.integrator().iteration_cap().is_none() {
        sim.integrator()
    } else {
        Integrator::Symplectic
    };
    let stable = estimate.max_dt(explicit);
    let crossing = tunnelling(scene)
        .iter()
        .map(|t| t.safe_dt)
        .chain(layer_limit(scene))
        .fold(f64::INFINITY, f64::min);
    if dt <= stable && dt <= crossing {
        return Advice {
            integrator: explicit,
            why: format!(
                "dt = {} s is within {explicit}'s stable step ({stable:.3e} s) and no particle \
                 can pass through a collider or another layer in one step at it",
                Num(dt)
            ),
        };
    }
    let limit = if dt > stable {
        format!("above {explicit}'s stable step ({stable:.3e} s)")
    } else {
        format!("above the step that keeps contacts from being crossed ({crossing:.3e} s)")
    };
    let stiff = volumetric_bodies(scene);
    if !stiff.is_empty()
        && let Some(cost) = newton_cost(scene)
    {
        // One recommendation, consistent with the warning `run` gives for Newton here.
        return Advice {
            integrator: Integrator::Vbd,
            why: format!(
                "dt = {} s is {limit}; {} a volumetric or stiff body, on which Newton's global \
                 solve converges faster, but {cost}; block descent keeps the same bounds, and \
                 its steps on that body may end at their iteration budget",
                Num(dt),
                subject(&stiff.into_iter().map(|(name, _)| name).collect::<Vec<_>>())
            ),
        };
    }
    if !stiff.is_empty() {
        return Advice {
            integrator: Integrator::Newton,
            why: format!(
                "dt = {} s is {limit}; {} a volumetric or stiff body, which Newton's global solve \
                 converges on in a few iterations where block descent's sweeps crawl",
                Num(dt),
                subject(&stiff.into_iter().map(|(name, _)| name).collect::<Vec<_>>())
            ),
        };
    }
    Advice {
        integrator: Integrator::Vbd,
        why: format!(
            "dt = {} s is {limit}; block descent takes one implicit step per frame that keeps \
             every body out of the colliders{}",
            Num(dt),
            if scene.bodies.iter().any(|b| b.thickness > 0.0) {
                " and the surfaces out of each other"
            } else {
                ""
            }
        ),
    }
}

/// The bodies `named`, as a sentence's subject: `body 'a' is`, `bodies 'a', 'b' are`.
fn subject(named: &[String]) -> String {
    let quoted: Vec<String> = named.iter().map(|n| format!("'{n}'")).collect();
    match quoted.len() {
        1 => format!("body {} is", quoted[0]),
        _ => format!("bodies {} are", quoted.join(", ")),
    }
}

/// What each body keeps from the colliders under a large step: its surface's thickness, or
/// a point's.
fn kept(scene: &Scene) -> String {
    let point = scene.simulation.model().point_thickness();
    scene
        .bodies
        .iter()
        .map(|b| {
            let what = match b.topology {
                Topology::Chain => "a chain",
                Topology::Grid(_) => "a grid",
                Topology::Lattice(_) => "a lattice",
                Topology::Points => "points",
                Topology::Mesh => "a cloth mesh",
                Topology::Solid => "a filled mesh",
            };
            if b.thickness > 0.0 {
                format!(
                    "'{}' ({what}) keeps its {:.1} mm thickness",
                    b.name,
                    b.thickness * 1e3
                )
            } else {
                format!(
                    "'{}' ({what}) keeps {:.2} mm as points",
                    b.name,
                    point * 1e3
                )
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The promises of a large step (`vbd`, `newton`) on `scene`, body by body, and what no
/// integrator promises here.
pub(crate) fn large_step_promises(scene: &Scene, integrator: Integrator) -> Vec<String> {
    let model = scene.simulation.model();
    let name = integrator.name();
    // Block descent's steps gain energy when left unsolved (a swinging sheet does at the
    // defaults); Newton's line search takes no move that raises the step's energy.
    let stable = if integrator == Integrator::Newton {
        "stability at any dt; "
    } else {
        ""
    };
    let mut out = vec![format!(
        "{name} guarantees: {stable}no particle of any body crosses a still restitution or \
         stick collider at any dt (every update is bounded, docs/physics.md §4.1): {}",
        kept(scene)
    )];
    let surfaces: Vec<&str> = scene
        .bodies
        .iter()
        .filter(|b| b.thickness > 0.0)
        .map(|b| b.name.as_str())
        .collect();
    if !surfaces.is_empty() {
        out.push(format!(
            "{name} guarantees: no surface crosses another or itself at any dt (bodies with a \
             contact thickness: '{}'), but where a crease brings two points of one surface \
             that were within {:.1} mm of each other at rest, and near along it, to within its \
             thickness (its own contacts there are skipped, docs/physics.md §4.1; a run says \
             so at each step where such a crease has crossed, §3.5); bodies without one ({}) \
             are not kept apart from each other",
            surfaces.join("', '"),
            1e3 * model.self_contact_skip(),
            {
                let others: Vec<String> = scene
                    .bodies
                    .iter()
                    .filter(|b| b.thickness == 0.0)
                    .map(|b| format!("'{}'", b.name))
                    .collect();
                if others.is_empty() {
                    "none here".to_string()
                } else {
                    others.join(", ")
                }
            }
        ));
    }
    for (k, slot) in model.colliders.iter().enumerate() {
        if slot.response.is_force() {
            out.push(format!(
                "no integrator keeps particles out of collider[{k}] ({}): it is a penalty wall, \
                 the course's force field, which every body may enter by design",
                slot.shape.name()
            ));
        }
    }
    if scene.has_moving_colliders() || !model.pin_motions.is_empty() {
        out.push(format!(
            "a moving or deforming collider or moving pins are followed in parts of the step, down to dt/{}; \
             where a pinned or squeezed particle lies in a moving collider's path no integrator \
             can keep the bound, and the run warns at the step it happens",
            hooke_core::MOST_PARTS
        ));
    }
    out.push(
        "a run whose energy grows by more than a hundredth of its scale beyond the work done \
         on it (field, air, attachments, moving pins, moving colliders) stops as diverged"
            .to_string(),
    );
    out
}

/// Why Newton is a poor choice for `scene` (none when it is not): its cost where a collider
/// or pins move and the step is taken in parts.
pub(crate) fn newton_cost(scene: &Scene) -> Option<String> {
    let model = scene.simulation.model();
    let moving = scene.has_moving_colliders() || !model.pin_motions.is_empty();
    let surfaces = scene.bodies.iter().any(|b| b.thickness > 0.0);
    (moving && surfaces).then(|| {
        "newton with a moving collider or moving pins takes every part of a split step (up to \
         4096 a step) as a global solve with a fresh detection: about twice block descent's \
         time where a collider sweeps slowly through a cloth, and 70 times where a fast one \
         splits steps into hundreds of parts (a ball thrown through a hanging cloth at 30 m/s: \
         572 s against 8.3 s); for cloth, `--integrator vbd` keeps the same bounds"
            .to_string()
    })
}

/// Warns on stderr when a large step runs a scene that `hooke check` steers to the other
/// one: block descent on a lattice or stiff body (its steps end unsolved), Newton where a
/// collider or pins move (each part of a split step is a global solve).
pub(crate) fn warn_if_other_large_step(scene: &Scene, estimate: &StabilityEstimate) {
    let sim = &scene.simulation;
    let integrator = sim.integrator();
    if !integrator.solves_contacts() {
        return;
    }
    if integrator == Integrator::Newton {
        if let Some(cost) = newton_cost(scene) {
            eprintln!("warning: {cost}");
        }
        return;
    }
    let advice = recommend(scene, estimate, sim.dt());
    if advice.integrator == Integrator::Newton {
        for (_, message) in volumetric_bodies(scene) {
            eprintln!("warning: {message}; `hooke check` recommends newton here");
        }
    }
}
