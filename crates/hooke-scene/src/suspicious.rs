//! What a scene as built does that its author probably did not mean: bodies that start
//! inside a collider, cloth that starts below the top of a table it hangs over (it falls
//! beside or under the table and wraps its pedestal instead of landing on it), tables of a
//! single triangle, and surfaces that start too near each other (`crate::overlaps`). Said
//! as warnings: such scenes still run.

use crate::scene::{ColliderGeometry, Scene};
use hooke_core::{Num, Vec3};

/// The top height and horizontal extent (`[x_min, z_min]`, `[x_max, z_max]`) of a table-like
/// collider: a mesh or the analytic cylinder.
fn table_extent(geometry: &ColliderGeometry) -> Option<(f64, [f64; 2], [f64; 2])> {
    match geometry {
        ColliderGeometry::Cylinder(c) => Some((
            c.center.y,
            [c.center.x - c.radius, c.center.z - c.radius],
            [c.center.x + c.radius, c.center.z + c.radius],
        )),
        ColliderGeometry::Mesh(triangles) if !triangles.is_empty() => {
            let points = triangles.iter().flatten();
            let (lo, hi) = points.fold(
                (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |(lo, hi), p| (lo.inf(p), hi.sup(p)),
            );
            Some((hi.y, [lo.x, lo.z], [hi.x, hi.z]))
        }
        _ => None,
    }
}

impl Scene {
    /// Warnings about the scene as built (see the module's documentation), one line each;
    /// none for the built-in scenes.
    pub fn warnings(&self) -> Vec<String> {
        let mut said = self.build_warnings.clone();
        let x = &self.simulation.particles().x;
        let slots = &self.simulation.model().colliders;
        for (k, geometry) in self.colliders.iter().enumerate() {
            if let ColliderGeometry::Mesh(triangles) = geometry
                && triangles.len() == 1
            {
                said.push(format!(
                    "collider[{k}] is a mesh of a single triangle: an open sheet, not a table"
                ));
            }
        }
        for (b, spec) in self.spec.bodies.iter().enumerate() {
            let Some(keys) = spec.pin_motion.as_ref().and_then(|m| m.keyframes().ok()) else {
                continue;
            };
            // The pins sit where the keys put them at t = 0 from the first step on.
            let (translate, rotate) = keys.at(0.0);
            if translate != Vec3::zeros() || rotate != Vec3::zeros() {
                let first = keys.keys()[0].t;
                said.push(format!(
                    "body[{b}] '{}': its pin_motion puts the pins {} m away{} at t = 0{}, so \
                     they jump there at the first step and pull the body after them; start \
                     the keys with {{ t = 0, translate = [0, 0, 0] }}",
                    spec.name,
                    hooke_core::Approx(translate.norm()),
                    if rotate != Vec3::zeros() {
                        format!(
                            ", turned by ({}°, {}°, {}°)",
                            hooke_core::Approx(rotate.x),
                            hooke_core::Approx(rotate.y),
                            hooke_core::Approx(rotate.z)
                        )
                    } else {
                        String::new()
                    },
                    if first > 0.0 {
                        format!(
                            " (its first key, at t = {} s, holds before it)",
                            hooke_core::Approx(first)
                        )
                    } else if keys.keys().iter().all(|k| k.t < 0.0) {
                        " (every key is before t = 0: the last one's pose holds from the start)"
                            .to_string()
                    } else {
                        String::new()
                    }
                ));
            }
        }
        said.extend(self.caches_away_or_short());
        said.extend(self.pins_into_colliders());
        said.extend(self.ignored_stop_rule());
        for moved in &self.pushed_out {
            said.push(format!(
                "{} particle{} started inside collider[{}] ({}) or nearer it than their \
                 thickness, and {} moved out before the first step, by up to {} m",
                moved.particles,
                if moved.particles == 1 { "" } else { "s" },
                moved.collider,
                slots[moved.collider].shape.name(),
                if moved.particles == 1 { "was" } else { "were" },
                Num(moved.deepest)
            ));
        }
        for body in &self.bodies {
            let points = &x[body.range.clone()];
            for (k, slot) in slots.iter().enumerate() {
                // Velocity-level colliders were dealt with before the first step.
                if !slot.response.is_force() {
                    continue;
                }
                let inside = points.iter().filter(|p| slot.shape.inside(p)).count();
                if inside > 0 {
                    said.push(format!(
                        "body '{}' starts with {inside} of its {} particles inside collider[{k}] \
                         ({}): its penalty springs push them out in the first steps",
                        body.name,
                        points.len(),
                        slot.shape.name()
                    ));
                }
            }
            if body.triangles.is_empty() {
                continue;
            }
            for (k, geometry) in self.colliders.iter().enumerate() {
                let Some((top, lo, hi)) = table_extent(geometry) else {
                    continue;
                };
                let over =
                    |p: &&Vec3| (lo[0]..=hi[0]).contains(&p.x) && (lo[1]..=hi[1]).contains(&p.z);
                let below = points.iter().filter(over).filter(|p| p.y < top).count();
                if below > 0 {
                    said.push(format!(
                        "body '{}' starts with {below} particles over collider[{k}] but below its \
                         top (y = {} m): it falls beside or under the table instead of onto it; \
                         raise the body's origin above the top",
                        body.name,
                        Num(top)
                    ));
                }
            }
        }
        said.extend(crate::overlaps::overlapping_bodies(self));
        said.extend(crate::overlaps::overlapping_pieces(self));
        said
    }

    /// Caches that start away or end early: pins whose cache's first sample is not where
    /// they start (they jump there at the first step and pull the body after them), and
    /// caches whose last sample comes before the run ends (their mesh or pins hold there).
    fn caches_away_or_short(&self) -> Vec<String> {
        let mut said = Vec::new();
        let model = self.simulation.model();
        let end = self.steps as f64 * self.simulation.dt();
        let x = &self.simulation.particles().x;
        for motion in &model.pin_motions {
            if !matches!(motion.path, hooke_core::PinPath::Track { .. }) {
                continue;
            }
            let away = motion
                .positions(0.0)
                .map(|(i, at)| (at - x[i]).norm())
                .fold(0.0, f64::max);
            let b = self.bodies.iter().position(|b| {
                motion
                    .particles
                    .first()
                    .is_some_and(|&i| b.range.contains(&(i as usize)))
            });
            if let Some(b) = b
                && away > 1e-6
            {
                said.push(format!(
                    "body[{b}] '{}': its pin_motion cache puts a pin {} m from where it starts \
                     at t = 0, so the pins jump there at the first step and pull the body after \
                     them; write the cache from the body's own vertices (sample 0 where they \
                     are) or place the body on it",
                    self.bodies[b].name,
                    hooke_core::Approx(away)
                ));
            }
            let last = motion.times().last().copied().unwrap_or(0.0);
            if let Some(b) = b
                && last < end - 1e-9
            {
                said.push(format!(
                    "body[{b}] '{}': its pin_motion cache ends at t = {} s and the run at {} s: \
                     the pins hold their last sample from then on",
                    self.bodies[b].name,
                    hooke_core::Approx(last),
                    hooke_core::Approx(end)
                ));
            }
        }
        for (k, animation) in self.animations.iter().enumerate() {
            if let Some(a) = animation
                && a.cache().duration() < end - 1e-9
            {
                said.push(format!(
                    "collider[{k}] ({}): its cache ends at t = {} s and the run at {} s: the \
                     mesh holds its last sample from then on",
                    model.colliders[k].shape.name(),
                    hooke_core::Approx(a.cache().duration()),
                    hooke_core::Approx(end)
                ));
            }
        }
        said
    }

    /// Keyed pins that their keys take into a still collider: they drag their body in after
    /// them, which no integrator prevents (a pin is moved by its keys, not by contacts).
    /// Sampled at every key and at 64 times between two keys.
    fn pins_into_colliders(&self) -> Vec<String> {
        const SAMPLES: usize = 64;
        let model = self.simulation.model();
        let mut said = Vec::new();
        for motion in &model.pin_motions {
            let turns = motion.times();
            let times: Vec<f64> = turns
                .windows(2)
                .flat_map(|w| {
                    (0..SAMPLES).map(move |k| w[0] + (w[1] - w[0]) * k as f64 / SAMPLES as f64)
                })
                .chain(turns.last().copied())
                .filter(|t| *t >= 0.0)
                .collect();
            'colliders: for (k, slot) in model.colliders.iter().enumerate() {
                if slot.shape.is_moving() {
                    continue;
                }
                for &t in &times {
                    if let Some((i, _)) = motion.positions(t).find(|(_, x)| slot.shape.inside(x)) {
                        let body = self
                            .bodies
                            .iter()
                            .find(|b| b.range.contains(&i))
                            .map_or(String::new(), |b| format!(" of body '{}'", b.name));
                        said.push(format!(
                            "the moving pins{body} enter collider[{k}] ({}) by t = {} s: a pin \
                             follows its motion whatever is in its way, and drags its body into \
                             the collider after it under every integrator; move the pins clear \
                             of it",
                            slot.shape.name(),
                            hooke_core::Approx(t)
                        ));
                        continue 'colliders;
                    }
                }
            }
        }
        said
    }

    /// A stopping rule (`tolerance`, `iterations`) given to an integrator that takes none:
    /// only `vbd` and `newton` iterate to one.
    fn ignored_stop_rule(&self) -> Vec<String> {
        let sim = &self.spec.simulation;
        let integrator = self.simulation.integrator();
        if integrator.solves_contacts() {
            return Vec::new();
        }
        [
            ("tolerance", sim.tolerance.is_some()),
            ("iterations", sim.iterations.is_some()),
        ]
        .into_iter()
        .filter(|(_, given)| *given)
        .map(|(key, _)| {
            format!(
                "{key} (--{key}) is block descent's and Newton's stopping rule; {integrator} \
                 takes none, so it has no effect here (use --integrator vbd or newton)"
            )
        })
        .collect()
    }
}
