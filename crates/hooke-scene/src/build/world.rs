//! A scene's colliders (with their drawing geometry) and its force field.

use crate::colliders::{build_collider, cache_of, deforming, response};
use crate::error::{BuildError, invalid};
use crate::limits::MAX_PENALTY;
use crate::scene::ColliderGeometry;
use crate::spec::*;
use hooke_core::Num;
use hooke_core::{ColliderSlot, ForceField, Vec3};
use std::path::Path;
use std::sync::Arc;

/// The built colliders, their drawing geometry and the deforming meshes' animations, each
/// in file order.
pub(super) type Colliders = (
    Vec<ColliderSlot>,
    Vec<ColliderGeometry>,
    Vec<Option<Arc<hooke_collide::MeshAnimation>>>,
);

impl SceneSpec {
    /// The colliders in file order, with their geometry for drawing (and, for a mesh its
    /// cache deforms, the animation); an inclined plane is placed relative to the bodies'
    /// `centroid`.
    pub(super) fn build_colliders(
        &self,
        base: &Path,
        centroid: &Vec3,
    ) -> Result<Colliders, BuildError> {
        let mut slots = Vec::new();
        let mut geometry = Vec::new();
        let mut animations = Vec::new();
        for (c, spec) in self.colliders.iter().enumerate() {
            let key = format!("collider[{c}]");
            // Penalty forces need an inside: a mesh under one must be a closed solid. The
            // velocity responses also catch crossings, so open sheets work with them.
            let solid = matches!(spec.response, ResponseSpec::Penalty { .. });
            if let ResponseSpec::Penalty { kc, dc } = spec.response {
                for (name, value, unit) in [("kc", kc.get(), "N/m"), ("dc", dc.get(), "N·s/m")] {
                    if value > MAX_PENALTY {
                        return Err(invalid(
                            format!("{key}.response.{name}"),
                            format!(
                                "{} {unit} is beyond what a step can follow or the energy can \
                                 hold: expected at most {MAX_PENALTY:e} {unit}",
                                Num(value)
                            ),
                        ));
                    }
                }
            }
            let cache = match &spec.motion {
                Some(motion) => cache_of(motion, &format!("{key}.motion"))?,
                None => None,
            };
            if let Some(cache) = cache {
                let mesh = deforming(&spec.shape, cache, &key, (base, solid))?;
                geometry.push(ColliderGeometry::Mesh(mesh.animation().triangles_at(0.0)));
                animations.push(Some(mesh.animation()));
                slots.push(ColliderSlot {
                    shape: Box::new(mesh),
                    response: response(&spec.response),
                });
                continue;
            }
            let (mut shape, geo) = build_collider(&spec.shape, &key, base, centroid, solid)?;
            if let Some(motion) = &spec.motion {
                shape = crate::colliders::moving(shape, &spec.shape, motion, &key)?;
            }
            slots.push(ColliderSlot {
                shape,
                response: response(&spec.response),
            });
            geometry.push(geo);
            animations.push(None);
        }
        Ok((slots, geometry, animations))
    }

    /// The force field, or `None` when there is none or it is zero everywhere.
    pub(super) fn build_field(&self) -> Result<Option<ForceField>, BuildError> {
        Ok(match &self.force_field {
            None => None,
            Some(f) if f.resolution == 0 => None,
            Some(f) => {
                let values = f.values.iter().map(vec3).collect::<Vec<_>>();
                let found = values.len();
                let field = ForceField::new(f.resolution, values).ok_or_else(|| {
                    invalid(
                        "force_field.values",
                        format!(
                            "expected resolution³ = {} vectors, found {found}",
                            f.resolution.saturating_pow(3)
                        ),
                    )
                })?;
                // A field that is zero everywhere (as in most of the course's worlds) adds
                // nothing, and sampling it costs a fifth of a jelly's step: leave it out.
                // Forces are the same numbers (at most a -0 becomes +0).
                (!field.is_zero()).then_some(field)
            }
        })
    }
}
