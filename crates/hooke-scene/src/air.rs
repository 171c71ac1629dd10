//! Air on a scene: the checks on its wind and density, and the triangles of each body it
//! acts on (docs/physics.md §1).

use crate::error::{BuildError, invalid};
use crate::limits::{MAX_AIR_DENSITY, MAX_WIND};
use crate::spec::*;
use hooke_core::{AeroSurface, Num, Vec3};

/// Refuses air whose wind (steady plus the gust's largest change) reaches [`MAX_WIND`].
pub(crate) fn check_air(air: &AirSpec) -> Result<(), BuildError> {
    let density = air.density.get();
    if density > MAX_AIR_DENSITY {
        return Err(invalid(
            "simulation.air.density",
            format!(
                "{} kg/m³ is denser than any fluid (water is 1000, mercury 13,534): expected at \
                 most {MAX_AIR_DENSITY:e} kg/m³ (sea-level air is 1.225)",
                Num(density)
            ),
        ));
    }
    let wind = vec3(&air.wind);
    let gust = air.gust.map_or(Vec3::zeros(), |g| vec3(&g.amplitude));
    let fastest = wind.norm() + gust.norm();
    if fastest.is_finite() && fastest < MAX_WIND {
        return Ok(());
    }
    let key = if gust.norm() > wind.norm() {
        "simulation.air.gust.amplitude"
    } else {
        "simulation.air.wind"
    };
    let shown = |v: &Vec3| format!("[{}, {}, {}]", Num(v.x), Num(v.y), Num(v.z));
    Err(invalid(
        key,
        format!(
            "a wind of {} m/s with gusts of {} m/s reaches {} m/s; Hooke's air is \
             incompressible drag, which means nothing at or beyond the speed of sound: expected \
             less than {MAX_WIND} m/s in all",
            shown(&wind),
            shown(&gust),
            if fastest.is_finite() {
                format!("{fastest:.1}")
            } else {
                "far beyond any number".to_string()
            }
        ),
    ))
}

/// The triangles of a body that the air acts on, with its coefficients: none without air.
pub(crate) fn body_aero(
    body: &BodySpec,
    key: &str,
    triangles: &[[u32; 3]],
    air: Option<AirSpec>,
) -> Result<Option<AeroSurface>, BuildError> {
    if body.aero.is_some() && triangles.is_empty() {
        return Err(invalid(
            format!("{key}.aero"),
            "only bodies with a surface (grid, lattice) feel air; remove it",
        ));
    }
    if air.is_none() || triangles.is_empty() {
        return Ok(None);
    }
    let coefficients = body.aero.unwrap_or_default();
    Ok(Some(AeroSurface {
        triangles: triangles.to_vec(),
        drag: coefficients.drag.get(),
        lift: coefficients.lift.get(),
    }))
}
