//! What a scene as built does that its author probably did not mean: bodies that start
//! inside a collider, cloth that starts below the top of a table it hangs over (it falls
//! beside or under the table and wraps its pedestal instead of landing on it), tables of a
//! single triangle. Said as warnings: such scenes still run.

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
        said.extend(self.overlapping_bodies());
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
            let keys = motion.keys.keys();
            let times: Vec<f64> = keys
                .windows(2)
                .flat_map(|w| {
                    (0..SAMPLES)
                        .map(move |k| w[0].t + (w[1].t - w[0].t) * k as f64 / SAMPLES as f64)
                })
                .chain(keys.last().map(|k| k.t))
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
                            "the keyed pins{body} enter collider[{k}] ({}) by t = {} s: a pin \
                             follows its keys whatever is in its way, and drags its body into \
                             the collider after it under every integrator; key the pins clear \
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

    /// Pairs of bodies that start through each other, or nearer than the sum of their
    /// contact thicknesses: a spring of one passing that near a triangle of the other.
    fn overlapping_bodies(&self) -> Vec<String> {
        let x = &self.simulation.particles().x;
        let springs = &self.simulation.model().springs;
        let mut said = Vec::new();
        for (a, body) in self.bodies.iter().enumerate() {
            for (b, other) in self.bodies.iter().enumerate() {
                if a == b || other.triangles.is_empty() || (a > b && !body.triangles.is_empty()) {
                    // Each pair once, but a body without triangles only from its side.
                    continue;
                }
                let reach = body.thickness + other.thickness;
                let mut near =
                    spring_triangle_hits(x, springs, &body.range, &other.triangles, reach);
                if !body.triangles.is_empty() {
                    near += spring_triangle_hits(x, springs, &other.range, &body.triangles, reach);
                }
                if near > 0 {
                    said.push(format!(
                        "bodies '{}' and '{}' start through each other or nearer than their \
                         contact thicknesses ({} m together): {near} of their springs pass \
                         that near the other's surface, and the contacts will tear them apart \
                         in the first steps; start them further apart",
                        body.name,
                        other.name,
                        Num(reach)
                    ));
                }
            }
        }
        said
    }
}

/// How many springs with both ends in `range` pass within `reach` (or through) any of
/// `triangles`, found through a uniform grid of the triangles' boxes.
fn spring_triangle_hits(
    x: &[Vec3],
    springs: &[hooke_core::Spring],
    range: &std::ops::Range<usize>,
    triangles: &[[u32; 3]],
    reach: f64,
) -> usize {
    use hooke_core::contact::proximity::segment_triangle;
    use std::collections::HashMap;
    let corners = |t: &[u32; 3]| t.map(|i| x[i as usize]);
    let bounds = |points: &[Vec3]| {
        let inf = Vec3::repeat(f64::INFINITY);
        points
            .iter()
            .fold((inf, -inf), |(lo, hi), p| (lo.inf(p), hi.sup(p)))
    };
    let mine: Vec<&hooke_core::Spring> = springs
        .iter()
        .filter(|s| range.contains(&(s.i as usize)) && range.contains(&(s.j as usize)))
        .collect();
    let (lo_a, hi_a) = bounds(&x[range.clone()]);
    let (lo_b, hi_b) = bounds(&triangles.iter().flat_map(corners).collect::<Vec<_>>());
    let apart = (0..3).any(|k| lo_a[k] > hi_b[k] + reach || lo_b[k] > hi_a[k] + reach);
    if mine.is_empty() || apart {
        return 0;
    }
    // Cells about a triangle's size: each spring meets a few.
    let longest = triangles
        .iter()
        .map(|t| {
            let [p, q, r] = corners(t);
            (p - q).norm().max((q - r).norm()).max((r - p).norm())
        })
        .fold(0.0f64, f64::max);
    let cell = longest.max(reach).max(1e-6);
    let key = |p: &Vec3| p.map(|c| (c / cell).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (k, t) in triangles.iter().enumerate() {
        let (lo, hi) = bounds(&corners(t));
        let (lo, hi) = (key(&lo.add_scalar(-reach)), key(&hi.add_scalar(reach)));
        for i in lo.x..=hi.x {
            for j in lo.y..=hi.y {
                for l in lo.z..=hi.z {
                    grid.entry([i, j, l]).or_default().push(k);
                }
            }
        }
    }
    let reach2 = reach.max(1e-9).powi(2);
    mine.iter()
        .filter(|s| {
            let (p, q) = (x[s.i as usize], x[s.j as usize]);
            let (lo, hi) = bounds(&[p, q]);
            let (lo, hi) = (key(&lo), key(&hi));
            let mut seen = std::collections::HashSet::new();
            for i in lo.x..=hi.x {
                for j in lo.y..=hi.y {
                    for l in lo.z..=hi.z {
                        for &k in grid.get(&[i, j, l]).into_iter().flatten() {
                            if !seen.insert(k) {
                                continue;
                            }
                            let [a, b, c] = corners(&triangles[k]);
                            let (t, w) = segment_triangle(&p, &q, &a, &b, &c);
                            let on_segment = p + (q - p) * t;
                            let on_triangle = a * w[0] + b * w[1] + c * w[2];
                            if (on_segment - on_triangle).norm_squared() < reach2 {
                                return true;
                            }
                        }
                    }
                }
            }
            false
        })
        .count()
}
