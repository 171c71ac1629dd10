//! The bodies of a scene: each one's particles placed, pins, springs, surface, air
//! triangles and mesh, appended in file order.

use crate::air::body_aero;
use crate::body::{build_body, pin_motion};
use crate::contact_surface::body_surface;
use crate::error::{BuildError, invalid};
use crate::limits::{MAX_PARTICLES, particle_count};
use crate::scene::Body;
use crate::spec::*;
use hooke_core::{AeroSurface, Num, PinMotion, SANE_BOUND};
use hooke_core::{Particles, Spring, Surface, Vec3};
use std::path::Path;

impl SceneSpec {
    /// Every body's particles, springs, contact surface and air triangles, in file order.
    pub(super) fn build_bodies(&self, base: &Path) -> Result<Bodies, BuildError> {
        let mut out = Bodies::default();
        for (b, body) in self.bodies.iter().enumerate() {
            let key = format!("body[{b}] '{}'", body.name);
            // Exports and messages name bodies: two of one name could not be told apart.
            if let Some(first) = self.bodies[..b].iter().position(|o| o.name == body.name) {
                return Err(invalid(
                    format!("{key}.name"),
                    format!(
                        "body[{first}] already has the name '{}'; names must differ",
                        body.name
                    ),
                ));
            }
            self.build_body_into(body, &key, base, &mut out)?;
        }
        Ok(out)
    }

    /// One body appended to `out`.
    fn build_body_into(
        &self,
        body: &BodySpec,
        key: &str,
        base: &Path,
        out: &mut Bodies,
    ) -> Result<(), BuildError> {
        let particles = &mut out.particles;
        let start = particles.len();
        let too_many = |count: Option<usize>| {
            count
                .and_then(|n| n.checked_add(start))
                .is_none_or(|n| n > MAX_PARTICLES)
                .then(|| {
                    invalid(
                        format!("{key}.shape"),
                        format!("the scene would have more than {MAX_PARTICLES} particles"),
                    )
                })
        };
        // Checked before anything is allocated; a mesh's count is known once it is read
        // (which is bounded on its own), and checked then with the bodies before it.
        if let Some(e) = too_many(particle_count(&body.shape)) {
            return Err(e);
        }
        let built = build_body(body, key, particles.len(), base)?;
        let n = built.local.len();
        if let Some(e) = too_many(Some(n)) {
            return Err(e);
        }
        place_particles(body, key, (&built.local, &built.masses), particles)?;
        for (k, &pin) in built.pins.iter().enumerate() {
            if pin >= n {
                return Err(invalid(
                    format!("{key}.pins[{k}]"),
                    format!(
                        "particle {pin} does not exist; the body has {n} (0 to {})",
                        n - 1
                    ),
                ));
            }
            particles.pin(start + pin);
        }
        if body.pin_motion.is_some() {
            out.pin_motions
                .push(pin_motion(&built, body, key, start, particles, base)?);
        }
        out.springs.extend(built.springs);
        let triangles = match built.triangles {
            Some(t) => t.into_iter().map(|t| t.map(|i| i + start as u32)).collect(),
            None => crate::surface::triangles(built.topology, start),
        };
        let surface = body_surface(body, key, &built.local, start..start + n, triangles)?;
        if let Some(a) = body_aero(body, key, &surface.triangles, self.simulation.air)? {
            out.aero.push(a);
        }
        let skin = built.skin.map(|mut skin| {
            for v in &mut skin.vertices {
                v.offset(start as u32, &rotation(&body.rotate), &vec3(&body.origin));
            }
            std::sync::Arc::new(skin)
        });
        out.warnings
            .extend(built.warnings.into_iter().map(|w| format!("{key}: {w}")));
        out.bodies.push(Body {
            name: body.name.clone(),
            range: start..start + n,
            topology: built.topology,
            triangles: surface.triangles.clone(),
            thickness: surface.thickness,
            skin,
        });
        if surface.is_active() {
            out.surfaces.push(surface);
        }
        Ok(())
    }
}

/// What the bodies of a scene add up to.
#[derive(Default)]
pub(super) struct Bodies {
    pub(super) particles: Particles,
    pub(super) springs: Vec<Spring>,
    pub(super) bodies: Vec<Body>,
    pub(super) surfaces: Vec<Surface>,
    pub(super) aero: Vec<AeroSurface>,
    pub(super) pin_motions: Vec<PinMotion>,
    pub(super) warnings: Vec<String>,
}

/// Pushes a body's particles: at its `positions`, or its local layout rotated and moved to
/// its origin; with its `velocities` or its one velocity. Refuses a count that does not
/// match and a particle beyond the world's extent.
fn place_particles(
    body: &BodySpec,
    key: &str,
    (local, masses): (&[Vec3], &[f64]),
    particles: &mut Particles,
) -> Result<(), BuildError> {
    let r = rotation(&body.rotate);
    let o = vec3(&body.origin);
    let n = local.len();
    if let Some(ps) = &body.positions
        && ps.len() != n
    {
        return Err(invalid(
            format!("{key}.positions"),
            format!(
                "expected {n} positions (one per particle), found {}",
                ps.len()
            ),
        ));
    }
    if let Some(vs) = &body.velocities
        && vs.len() != n
    {
        return Err(invalid(
            format!("{key}.velocities"),
            format!(
                "expected {n} velocities (one per particle), found {}",
                vs.len()
            ),
        ));
    }
    for (p, local) in local.iter().enumerate() {
        let x = match &body.positions {
            Some(ps) => vec3(&ps[p]),
            None => o + r * local,
        };
        let v = body
            .velocities
            .as_ref()
            .map_or(vec3(&body.velocity), |vs| vec3(&vs[p]));
        if x.amax().is_nan() || x.amax() > SANE_BOUND {
            let what = if body.positions.is_some() {
                "positions"
            } else {
                "origin"
            };
            return Err(invalid(
                format!("{key}.{what}"),
                format!(
                    "particle {p} would start at ({}, {}, {}), beyond {} m of the origin \
                     (the extent of a simulated world)",
                    Num(x.x),
                    Num(x.y),
                    Num(x.z),
                    Num(SANE_BOUND)
                ),
            ));
        }
        particles.push(x, v, masses[p]);
    }
    Ok(())
}
