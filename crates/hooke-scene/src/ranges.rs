//! Every number a scene gives has a range, and a value outside it is refused with its key
//! before anything is built. The ranges are wide — nothing a scene means is refused — and
//! say why they end where they do: past them a typo is the likely cause, and the numbers a
//! solver forms from the value (squares, `ks dt² / m`, energies) leave what doubles hold,
//! or a state leaves the bound beyond which a run counts as diverged.

use crate::error::{BuildError, invalid};
use crate::limits::{MAX_AIR_DENSITY, MAX_PENALTY, MAX_WIND};
use crate::spec::*;
use hooke_core::{Num, SANE_BOUND};

/// A range of one kind of quantity, for messages.
#[derive(Clone, Copy)]
struct Range {
    /// The least and largest value accepted (by magnitude for signed quantities).
    low: f64,
    high: f64,
    /// Whether negative values are accepted (then `low..=high` bounds the magnitude).
    signed: bool,
    /// What it is, with its unit, e.g. `a length in m`.
    what: &'static str,
    /// Why it ends there.
    why: &'static str,
}

const fn range(low: f64, high: f64, signed: bool, what: &'static str, why: &'static str) -> Range {
    Range {
        low,
        high,
        signed,
        what,
        why,
    }
}

/// Positions, translations, sizes: a state beyond [`SANE_BOUND`] counts as diverged.
const LENGTH: Range = range(
    0.0,
    SANE_BOUND,
    true,
    "a length in m",
    "a particle beyond 1e6 m of the origin counts as diverged",
);
/// Spacings, radii, thicknesses (positive).
const SIZE: Range = range(
    1e-9,
    SANE_BOUND,
    false,
    "a size in m",
    "below a nanometre the contact and stiffness terms leave what doubles hold, and a \
     particle beyond 1e6 m of the origin counts as diverged",
);
/// A body's contact thickness (zero turns contacts off).
const THICKNESS: Range = range(
    0.0,
    1.0,
    false,
    "a contact thickness in m",
    "a body kept a metre from everything is a mistake for millimetres",
);
/// Angles of rotations and keys.
const ANGLE: Range = range(
    0.0,
    1e6,
    true,
    "an angle in degrees",
    "a million degrees is nearly 2800 turns; more is a typo",
);
/// Key times.
const TIME: Range = range(
    0.0,
    1e9,
    true,
    "a time in s",
    "a billion seconds is 32 years of simulated time",
);
/// Velocities.
const SPEED: Range = range(
    0.0,
    1e6,
    true,
    "a velocity in m/s",
    "a body at 1e6 m/s leaves the range a run can hold within a second",
);
/// Gravity.
const ACCELERATION: Range = range(
    0.0,
    1e4,
    true,
    "an acceleration in m/s²",
    "1e4 m/s² is a thousand g",
);
/// Particle masses.
const MASS: Range = range(
    1e-12,
    1e6,
    false,
    "a mass in kg",
    "a nanogram to a thousand tonnes a particle; beyond them `ks dt² / m` and the energies \
     leave what doubles hold",
);
/// Spring stiffness.
const STIFFNESS: Range = range(
    0.0,
    MAX_PENALTY,
    false,
    "a stiffness in N/m",
    "a gram on 1e12 N/m rings at 3e7 rad/s, beyond any step a solver takes",
);
/// Damping coefficients.
const DAMPING: Range = range(
    0.0,
    MAX_PENALTY,
    false,
    "a damping coefficient in N·s/m",
    "beyond 1e12 N·s/m no step is stable and the rates leave what doubles hold",
);
/// Drag per particle.
const DRAG: Range = range(
    0.0,
    1e6,
    false,
    "a drag in N·s/m per particle",
    "1e6 N·s/m stops a kilogram in a microsecond",
);
/// Drag per kilogram.
const MASS_DRAG: Range = range(
    0.0,
    1e6,
    false,
    "a drag in N·s/m per kg (1/s)",
    "1e6 1/s stops any body in a microsecond",
);
/// Coulomb coefficients.
const FRICTION: Range = range(
    0.0,
    1e3,
    false,
    "a Coulomb friction coefficient",
    "real surfaces have μ below about 2; 1e3 is a typo (to hold, give `response = { kind = \"stick\" }`)",
);
/// Areal density of a material.
const AREAL_DENSITY: Range = range(
    1e-6,
    1e4,
    false,
    "an areal density in kg/m²",
    "fabrics weigh 0.02 to 1 kg/m²; 1e4 kg/m² is a 10 m layer of water",
);
/// A material's membrane stiffness per unit width.
const MEMBRANE: Range = range(
    0.0,
    1e9,
    false,
    "a membrane stiffness in N/m",
    "fabrics measure 10 to 1e5 N/m; 1e9 N/m is a steel sheet a millimetre thick",
);
/// A material's bending rigidity.
const BENDING: Range = range(
    0.0,
    1e3,
    false,
    "a bending rigidity in N·m",
    "fabrics measure 1e-7 to 1e-3 N·m; 1e3 N·m is a steel plate 5 cm thick",
);
/// A material's stiffness-proportional damping.
const DAMPING_TIME: Range = range(
    0.0,
    10.0,
    false,
    "a damping time in s",
    "β = 10 s damps every membrane mode in far less than a step; fabrics are near 1e-5 s",
);
/// Mesh scales.
const SCALE: Range = range(
    1e-9,
    SANE_BOUND,
    false,
    "a scale factor",
    "scaled by more than 1e6 a metre-sized mesh leaves the bound a state may reach",
);
/// Force-field values.
const FORCE: Range = range(
    0.0,
    1e12,
    true,
    "a force in N",
    "1e12 N throws any particle out of range in a step",
);
/// Aerodynamic coefficients.
const AERO: Range = range(
    0.0,
    1e3,
    true,
    "an aerodynamic coefficient",
    "drag and lift coefficients of real shapes are below about 3",
);
/// Periods and durations.
const PERIOD: Range = range(
    1e-15,
    1e9,
    false,
    "a time in s",
    "a billion seconds is 32 years of simulated time",
);
/// Air density.
const AIR_DENSITY: Range = range(
    1e-12,
    MAX_AIR_DENSITY,
    false,
    "a density in kg/m³",
    "denser than any liquid at hand",
);
/// Wind speeds.
const WIND: Range = range(
    0.0,
    MAX_WIND,
    true,
    "a wind speed in m/s",
    "the air model is incompressible drag, meaningless at the speed of sound",
);

/// A stopping tolerance.
const TOLERANCE: Range = range(
    1e-12,
    1e3,
    false,
    "a velocity in m/s",
    "a tolerance beyond 1e3 m/s stops every step at once; below 1e-12 m/s no iteration \
     reaches it",
);
/// The most iterations a step may take.
const MAX_ITERATIONS: u64 = 100_000;

/// Checks `value` (at `key`) against `r`.
fn check(key: &str, value: f64, r: Range) -> Result<(), BuildError> {
    let magnitude = if r.signed { value.abs() } else { value };
    let ok = value.is_finite() && (r.signed || value >= 0.0) && {
        magnitude <= r.high && (magnitude >= r.low || (r.signed && magnitude == 0.0))
    };
    // A zero is always a signed quantity's and an unsigned one's when the range starts at 0.
    if ok || (value == 0.0 && r.low == 0.0) {
        return Ok(());
    }
    // Round limits read best in powers of ten: `1e6`, not `1000000`.
    let limit = |x: f64| {
        if x != 0.0 && !(1e-3..1e4).contains(&x) {
            format!("{x:e}")
        } else {
            Num(x).to_string()
        }
    };
    let span = if r.signed {
        format!("within ±{}", limit(r.high))
    } else if r.low == 0.0 {
        format!("from 0 to {}", limit(r.high))
    } else {
        format!("from {} to {}", limit(r.low), limit(r.high))
    };
    Err(invalid(
        key,
        format!(
            "expected {} {span}, found {}: {}",
            r.what,
            Num(value),
            r.why
        ),
    ))
}

fn each<const N: usize>(key: &str, values: &[Finite; N], r: Range) -> Result<(), BuildError> {
    for (k, v) in values.iter().enumerate() {
        check(&format!("{key}[{k}]"), v.get(), r)?;
    }
    Ok(())
}

/// Checks every number of `spec` against its range (see the module's documentation).
pub(crate) fn check_ranges(spec: &SceneSpec) -> Result<(), BuildError> {
    let sim = &spec.simulation;
    // The run's length is checked in steps (`SceneSpec::total_steps`), which says more.
    if let Some(t) = sim.tolerance {
        check("simulation.tolerance", t.get(), TOLERANCE)?;
    }
    if let Some(n) = sim.iterations
        && !(1..=MAX_ITERATIONS).contains(&n)
    {
        return Err(invalid(
            "simulation.iterations",
            format!(
                "expected 1 to {MAX_ITERATIONS} iterations a step, found {n}: more is years \
                 of computing for a run"
            ),
        ));
    }
    each("simulation.gravity", &sim.gravity, ACCELERATION)?;
    check("simulation.drag", sim.drag.get(), DRAG)?;
    check("simulation.mass_drag", sim.mass_drag.get(), MASS_DRAG)?;
    if let Some(air) = &sim.air {
        check("simulation.air.density", air.density.get(), AIR_DENSITY)?;
        each("simulation.air.wind", &air.wind, WIND)?;
        if let Some(g) = &air.gust {
            each("simulation.air.gust.amplitude", &g.amplitude, WIND)?;
            check("simulation.air.gust.period", g.period.get(), PERIOD)?;
        }
    }
    for (b, body) in spec.bodies.iter().enumerate() {
        let key = |k: &str| format!("body[{b}].{k}");
        if let Some(m) = body.mass {
            check(&key("mass"), m.get(), MASS)?;
        }
        each(&key("origin"), &body.origin, LENGTH)?;
        each(&key("rotate"), &body.rotate, ANGLE)?;
        each(&key("velocity"), &body.velocity, SPEED)?;
        for (i, p) in body.positions.iter().flatten().enumerate() {
            each(&key(&format!("positions[{i}]")), p, LENGTH)?;
        }
        for (i, v) in body.velocities.iter().flatten().enumerate() {
            each(&key(&format!("velocities[{i}]")), v, SPEED)?;
        }
        match &body.shape {
            ShapeSpec::Chain { spacing, .. }
            | ShapeSpec::Grid { spacing, .. }
            | ShapeSpec::Lattice { spacing, .. } => {
                check(&key("shape.spacing"), spacing.get(), SIZE)?;
            }
            ShapeSpec::Points { positions } => {
                for (i, p) in positions.iter().enumerate() {
                    each(&key(&format!("shape.positions[{i}]")), p, LENGTH)?;
                }
            }
            ShapeSpec::Mesh { weld, .. } => {
                if let Some(w) = weld {
                    check(&key("shape.weld"), w.get(), SIZE)?;
                }
            }
            ShapeSpec::Solid { spacing, .. } => {
                check(&key("shape.spacing"), spacing.get(), SIZE)?;
            }
        }
        for (name, params) in [
            ("structural", body.springs.structural),
            ("shear", body.springs.shear),
            ("bend", body.springs.bend),
        ] {
            if let Some(p) = params {
                check(&key(&format!("springs.{name}.ks")), p.ks.get(), STIFFNESS)?;
                check(&key(&format!("springs.{name}.kd")), p.kd.get(), DAMPING)?;
            }
        }
        for (i, pair) in body.springs.pairs.iter().enumerate() {
            let k = |name: &str| key(&format!("springs.pairs[{i}].{name}"));
            check(&k("ks"), pair.ks.get(), STIFFNESS)?;
            check(&k("kd"), pair.kd.get(), DAMPING)?;
            if let Some(r) = pair.rest {
                check(&k("rest"), r.get(), LENGTH)?;
            }
        }
        if let Some(motion) = &body.pin_motion {
            motion_ranges(&key("pin_motion"), motion)?;
        }
        if let Some(m) = &body.material {
            let k = |name: &str| key(&format!("material.{name}"));
            if let Some(x) = m.density {
                check(&k("density"), x.get(), AREAL_DENSITY)?;
            }
            if let Some(x) = m.stretch {
                check(&k("stretch"), x.get(), MEMBRANE)?;
            }
            if let Some(x) = m.shear {
                check(&k("shear"), x.get(), MEMBRANE)?;
            }
            if let Some(x) = m.bending {
                check(&k("bending"), x.get(), BENDING)?;
            }
            if let Some(x) = m.damping {
                check(&k("damping"), x.get(), DAMPING_TIME)?;
            }
        }
        if let Some(t) = body.thickness {
            check(&key("thickness"), t.get(), THICKNESS)?;
        }
        if let Some(f) = body.friction {
            check(&key("friction"), f.get(), FRICTION)?;
        }
        if let Some(a) = &body.aero {
            check(&key("aero.drag"), a.drag.get(), AERO)?;
            check(&key("aero.lift"), a.lift.get(), AERO)?;
        }
    }
    for (c, collider) in spec.colliders.iter().enumerate() {
        let key = |k: &str| format!("collider[{c}].{k}");
        match &collider.shape {
            ColliderShapeSpec::Ground { height } => {
                check(&key("shape.height"), height.get(), LENGTH)?
            }
            ColliderShapeSpec::Plane { coefficients } => {
                // `a x + b y + c z + d`: the normal's scale is free, the offset a length
                // times it.
                for (k, v) in coefficients.iter().enumerate() {
                    check(&key(&format!("shape.coefficients[{k}]")), v.get(), LENGTH)?;
                }
            }
            ColliderShapeSpec::Box { min, max } => {
                each(&key("shape.min"), min, LENGTH)?;
                each(&key("shape.max"), max, LENGTH)?;
            }
            ColliderShapeSpec::Cylinder {
                center,
                radius,
                thickness,
            } => {
                each(&key("shape.center"), center, LENGTH)?;
                check(&key("shape.radius"), radius.get(), SIZE)?;
                check(&key("shape.thickness"), thickness.get(), SIZE)?;
            }
            ColliderShapeSpec::Sphere { center, radius } => {
                each(&key("shape.center"), center, LENGTH)?;
                check(&key("shape.radius"), radius.get(), SIZE)?;
            }
            ColliderShapeSpec::Mesh {
                translate,
                rotate,
                scale,
                ..
            } => {
                each(&key("shape.translate"), translate, LENGTH)?;
                each(&key("shape.rotate"), rotate, ANGLE)?;
                for (k, s) in scale.iter().enumerate() {
                    check(&key(&format!("shape.scale[{k}]")), s.get(), SCALE)?;
                }
            }
        }
        match collider.response {
            ResponseSpec::Penalty { kc, dc } => {
                check(&key("response.kc"), kc.get(), STIFFNESS)?;
                check(&key("response.dc"), dc.get(), DAMPING)?;
            }
            ResponseSpec::Restitution { friction, .. } => {
                check(&key("response.friction"), friction.get(), FRICTION)?;
            }
            ResponseSpec::Stick => {}
        }
        if let Some(motion) = &collider.motion {
            motion_ranges(&key("motion"), motion)?;
        }
    }
    if let Some(field) = &spec.force_field {
        for (i, v) in field.values.iter().enumerate() {
            each(&format!("force_field.values[{i}]"), v, FORCE)?;
        }
    }
    Ok(())
}

/// A motion's keys: times, translations and angles.
fn motion_ranges(key: &str, motion: &MotionSpec) -> Result<(), BuildError> {
    for (i, k) in motion.keys.iter().enumerate() {
        let key = format!("{key}.keys[{i}]");
        check(&format!("{key}.t"), k.t.get(), TIME)?;
        each(&format!("{key}.translate"), &k.translate, LENGTH)?;
        if let Some(r) = &k.rotate {
            each(&format!("{key}.rotate"), r, ANGLE)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_outside_their_range_are_refused_with_the_key_and_the_range() {
        let e = check("collider[1].shape.radius", 1e9, SIZE).unwrap_err();
        let said = e.to_string();
        assert!(said.starts_with("collider[1].shape.radius: "), "{said}");
        assert!(
            said.contains("found 1000000000") && said.contains("to 1e6"),
            "{said}"
        );
        assert!(check("k", -1e308, LENGTH).is_err());
        assert!(
            check("k", 1e300, ANGLE)
                .unwrap_err()
                .to_string()
                .contains("1e300")
        );
        assert!(check("k", 1e308, AREAL_DENSITY).is_err());
        assert!(check("k", -1.0, STIFFNESS).is_err());
        assert!(check("k", 5e-13, MASS).is_err());
        // Everyday values and zeros pass.
        for (v, r) in [
            (0.0, LENGTH),
            (-3.5, LENGTH),
            (0.0, STIFFNESS),
            (400.0, STIFFNESS),
            (-9.81, ACCELERATION),
            (0.15, AREAL_DENSITY),
            (1e-5, DAMPING_TIME),
            (0.0, THICKNESS),
            (360.0, ANGLE),
        ] {
            assert!(check("k", v, r).is_ok(), "{v}");
        }
    }
}
