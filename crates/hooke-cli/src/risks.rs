//! What a scene's step risks, said before it runs: instability, tunnelling through a
//! thin surface, and a step so small that block descent would do better.

use hooke_core::Num;
use hooke_core::{Integrator, StabilityEstimate};
use hooke_scene::Scene;

/// Warns on stderr when the scene's step exceeds the estimated stable step.
pub(crate) fn warn_if_unstable(scene: &Scene) -> StabilityEstimate {
    let sim = &scene.simulation;
    let estimate = sim.stability();
    let limit = estimate.max_dt(sim.integrator());
    if sim.dt() > limit {
        eprintln!(
            "warning: dt = {} s exceeds the estimated stable step of {} ({limit:.3e} s, ω_max = {:.4e} rad/s); the run may diverge",
            Num(sim.dt()),
            sim.integrator(),
            estimate.omega_max
        );
    }
    estimate
}

/// One thin collider against the fastest motion the scene can reach.
pub(crate) struct Tunnelling {
    collider: String,
    thickness: f64,
    speed: f64,
    drop: f64,
    /// The collider's own fastest keyed speed (zero for a still one), m/s.
    moving: f64,
    per_step: f64,
    /// The largest step that keeps a step's travel within half the thickness.
    pub(crate) safe_dt: f64,
}

/// For every collider with a finite thickness: how far the fastest particle moves in one
/// step. The speed is the larger of the fastest particle now and a free fall from the
/// highest particle to the ground (or the lowest particle): what a falling cloth reaches.
pub(crate) fn tunnelling(scene: &Scene) -> Vec<Tunnelling> {
    let sim = &scene.simulation;
    let model = sim.model();
    let (speed, drop) = fastest(scene);
    model
        .colliders
        .iter()
        .enumerate()
        .filter_map(|(k, slot)| {
            // A collider without thickness (an open sheet) is held by the crossing test,
            // not by depth: nothing to tunnel through.
            let thickness = slot.shape.thickness().filter(|t| *t > 0.0)?;
            // A moving collider closes on a particle at their speeds' sum at worst.
            let moving = collider_speed(scene, k);
            let closing = speed + moving;
            Some(Tunnelling {
                collider: slot.shape.name(),
                thickness,
                speed,
                drop,
                moving,
                per_step: closing * sim.dt(),
                safe_dt: if closing > 0.0 {
                    0.5 * thickness / closing
                } else {
                    f64::INFINITY
                },
            })
        })
        .collect()
}

impl Tunnelling {
    pub(crate) fn risky(&self) -> bool {
        self.per_step > 0.5 * self.thickness
    }

    pub(crate) fn describe(&self, dt: f64) -> String {
        let moving = if self.moving > 0.0 {
            format!(", and the collider moves at up to {:.2} m/s,", self.moving)
        } else {
            String::new()
        };
        format!(
            "{} is {:.1} mm thick at its thinnest; at {:.2} m/s (a fall of {:.2} m){moving} a \
             particle moves {:.1} mm per step of {} s relative to it",
            self.collider,
            self.thickness * 1e3,
            self.speed,
            self.drop,
            self.per_step * 1e3,
            Num(dt)
        )
    }
}

/// The fastest that any point of collider `k` moves along its keys, m/s (zero when it does
/// not move): per pair of keys, the translation's speed plus the turn's rate (the angles'
/// change, in radians, summed as a bound) times the farthest point's distance from the pivot.
/// A mesh its cache deforms: the fastest any vertex moves between two samples.
fn collider_speed(scene: &Scene, k: usize) -> f64 {
    if let Some(Some(animation)) = scene.animations.get(k) {
        return animation.cache().speed();
    }
    let Some(keys) = scene.spec.colliders[k]
        .motion
        .as_ref()
        .and_then(|m| m.keyframes().ok())
    else {
        return 0.0;
    };
    let Some(pose) = scene.collider_pose(k, 0.0) else {
        return 0.0;
    };
    let reach = scene.colliders[k]
        .triangles(pose.pivot, 0.0, (pose.pivot, pose.pivot))
        .iter()
        .flatten()
        .map(|p| (p - pose.pivot).norm())
        .fold(0.0, f64::max);
    keys.keys()
        .windows(2)
        .map(|w| {
            let dt = w[1].t - w[0].t;
            let turn = (w[1].rotate - w[0].rotate).map(f64::to_radians).abs().sum();
            ((w[1].translate - w[0].translate).norm() + turn * reach) / dt
        })
        .fold(0.0, f64::max)
}

/// The step that keeps two layers of a surface, closing at the fastest speed a particle can
/// move, from covering its thickness: the explicit contact phase's condition (none without
/// a surface, or without motion).
pub(crate) fn layer_limit(scene: &Scene) -> Option<f64> {
    let (speed, _) = fastest(scene);
    scene
        .bodies
        .iter()
        .filter(|b| b.thickness > 0.0 && speed > 0.0)
        .map(|b| b.thickness / (2.0 * speed))
        .reduce(f64::min)
}

/// The fastest a particle can move, m/s: the larger of the fastest now and a free fall from
/// the highest particle to the ground (or the lowest particle); and that fall's height.
fn fastest(scene: &Scene) -> (f64, f64) {
    let sim = &scene.simulation;
    let p = sim.particles();
    let top = p.x.iter().map(|x| x.y).fold(f64::NEG_INFINITY, f64::max);
    let mut bottom = p.x.iter().map(|x| x.y).fold(f64::INFINITY, f64::min);
    for c in &scene.colliders {
        if let hooke_scene::ColliderGeometry::Ground(h) = c {
            bottom = bottom.min(*h);
        }
    }
    let drop = (top - bottom).max(0.0);
    let fall = (2.0 * sim.model().gravity.norm() * drop).sqrt();
    let now = p.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    (fall.max(now), drop)
}

/// Below this explicit step (a tenth of a 60 Hz frame) `hooke check` recommends block
/// descent for a scene with contact surfaces.
const TINY_STEP: f64 = 1.0 / 600.0;

/// The recommendation of `hooke check` for a scene with contact surfaces stepped by an
/// explicit integrator whose stable step (or tunnelling-safe step) is tiny: block descent at
/// a display frame.
pub(crate) fn large_step_advice(scene: &Scene, estimate: &StabilityEstimate) -> Option<String> {
    let sim = &scene.simulation;
    if sim.integrator().solves_contacts()
        || !scene.bodies.iter().any(|b| b.thickness > 0.0)
        || !volumetric_bodies(scene).is_empty()
    {
        return None;
    }
    // The stable explicit step, and the step that keeps two layers closing at the fastest
    // speed from covering a thickness (the explicit contact phase's condition).
    let layers = layer_limit(scene).unwrap_or(f64::INFINITY);
    let limit = estimate.max_dt(Integrator::Symplectic).min(layers);
    if limit >= TINY_STEP {
        return None;
    }
    Some(format!(
        "recommendation: explicit steps here must stay below {limit:.3e} s ({:.0} steps per \
         simulated second); `--integrator vbd --dt 0.016666666666666666` takes one implicit \
         step per 60 Hz frame with no crossing, with its defaults (a step ends when its last \
         iteration moves no particle faster than {} m/s, or after {} iterations; \
         docs/physics.md §4.1)",
        1.0 / limit,
        hooke_core::StopRule::VBD.tolerance,
        hooke_core::StopRule::VBD.iterations
    ))
}

/// For each body with a contact thickness: a message when two of its layers, closing at
/// twice the fastest speed, can cover the thickness in one step, so that a proximity is not
/// seen before a crossing (`docs/physics.md` §3.3), with the largest safe step.
pub(crate) fn thin_surfaces(scene: &Scene) -> Vec<String> {
    let dt = scene.simulation.dt();
    let (speed, _) = fastest(scene);
    scene
        .bodies
        .iter()
        .filter(|b| b.thickness > 0.0 && 2.0 * speed * dt > b.thickness)
        .map(|b| {
            format!(
                "body '{}': two layers closing at {:.2} m/s move {:.1} mm per step of {} s, more \
                 than its contact thickness of {:.1} mm, so they can cross between two looks of the \
                 contacts (the run says so at a step where they did); use dt below {:.3e} s or a \
                 larger thickness",
                b.name,
                2.0 * speed,
                2.0 * speed * dt * 1e3,
                Num(dt),
                b.thickness * 1e3,
                b.thickness / (2.0 * speed)
            )
        })
        .collect()
}

/// Warns on stderr about thin colliders a particle can cross in one step. Block descent and
/// Newton bound every update so that nothing crosses whatever the step: no warning for them.
pub(crate) fn warn_if_tunnelling(scene: &Scene) {
    if scene.simulation.integrator().solves_contacts() {
        return;
    }
    let dt = scene.simulation.dt();
    for t in tunnelling(scene).iter().filter(|t| t.risky()) {
        eprintln!(
            "warning: {}: more than half its thickness, so a particle can pass through or be \
             pushed out the far side (tunnelling); use dt below {:.3e} s",
            t.describe(dt),
            t.safe_dt
        );
    }
    for message in thin_surfaces(scene) {
        eprintln!("warning: {message}");
    }
}

/// For block descent: the volumetric bodies (lattices), and the bodies whose springs are
/// stiff against their inertia at this step (`ks dt² / m` above [`STIFF`]), which it
/// converges on slowly (a disturbance crosses about one colour of particles per
/// iteration); each as its name and a message naming the integrator that solves the step
/// globally instead.
pub(crate) fn volumetric_bodies(scene: &Scene) -> Vec<(String, String)> {
    let sim = &scene.simulation;
    let dt = sim.dt();
    let model = sim.model();
    let masses = &sim.particles().mass;
    scene
        .bodies
        .iter()
        .filter_map(|b| {
            let stiffness = model
                .springs
                .iter()
                .filter(|s| b.range.contains(&(s.i as usize)))
                .map(|s| s.ks * dt * dt / masses[s.i as usize].min(masses[s.j as usize]))
                .filter(|r| r.is_finite())
                .fold(0.0, f64::max);
            let why = if matches!(
                b.topology,
                hooke_scene::Topology::Lattice(_) | hooke_scene::Topology::Solid
            ) {
                "is a volumetric lattice".to_string()
            } else if stiffness > STIFF {
                let mesh = if b.topology == hooke_scene::Topology::Mesh {
                    slivers(&b.triangles, &sim.particles().x)
                } else {
                    String::new()
                };
                format!("has springs with ks dt²/m up to {stiffness:.1e}{mesh}")
            } else {
                return None;
            };
            Some((
                b.name.clone(),
                format!(
                    "body '{}' {why}, which block descent converges on slowly (a disturbance \
                 crosses about one colour of particles per iteration; its steps end at their \
                 budget); `--integrator newton` solves each step globally (docs/physics.md \
                 §4.2)",
                    b.name
                ),
            ))
        })
        .collect()
}

/// The `ks dt² / m` above which block descent's steps end at their budget on a strip or
/// cloth (a 2000 N/m strip at 1 cm spacing is 1e5 at 1/60 s and diverged; the built-in
/// cloths are below 1e3).
const STIFF: f64 = 1e4;

/// What makes a cloth mesh stiff, said so its user can remesh it: its shortest and longest
/// edges and how many of its triangles are slivers (an edge under a tenth of their longest,
/// whose short springs set the step).
fn slivers(triangles: &[[u32; 3]], x: &[hooke_core::Vec3]) -> String {
    let (mut shortest, mut longest, mut thin) = (f64::INFINITY, 0.0f64, 0usize);
    for t in triangles {
        let edges =
            [(0, 1), (1, 2), (2, 0)].map(|(a, b)| (x[t[a] as usize] - x[t[b] as usize]).norm());
        let (lo, hi) = edges.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &e| {
            (lo.min(e), hi.max(e))
        });
        shortest = shortest.min(lo);
        longest = longest.max(hi);
        thin += usize::from(lo < 0.1 * hi);
    }
    if triangles.is_empty() {
        return String::new();
    }
    format!(
        " (its mesh's edges run from {:.3} mm to {:.1} mm{}; remesh it to even triangles, \
         for example with Blender's Remesh or Triangulate modifier)",
        shortest * 1e3,
        longest * 1e3,
        if thin > 0 {
            format!(
                ", and {thin} of its {} triangles are slivers, with an edge under a tenth of their longest",
                triangles.len()
            )
        } else {
            String::new()
        }
    )
}
