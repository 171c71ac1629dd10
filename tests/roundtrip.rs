//! Property tests of the parsers' round trips: a written `.w` world reads back identical,
//! and a printed scene loads back identical, for any values the formats can hold.

use hooke_core::{Integrator, Vec3};
use hooke_scene::spec::{Finite, NonNegative, Positive, SceneSpec};
use hooke_scene::world::{World, parse_world};
use proptest::prelude::*;
use std::path::Path;

/// Any finite number, from subnormals to 1e308, either sign.
fn finite() -> impl Strategy<Value = f64> {
    prop::num::f64::NORMAL | prop::num::f64::SUBNORMAL | prop::num::f64::ZERO
}

fn positive() -> impl Strategy<Value = f64> {
    prop::num::f64::POSITIVE.prop_filter("finite and non-zero", |x| x.is_finite() && *x > 0.0)
}

fn non_negative() -> impl Strategy<Value = f64> {
    prop::num::f64::POSITIVE | prop::num::f64::ZERO
}

fn vec3() -> impl Strategy<Value = Vec3> {
    (finite(), finite(), finite()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn world() -> impl Strategy<Value = World> {
    let plane = (finite(), finite(), finite(), finite())
        .prop_filter("a plane needs a normal", |(a, b, c, _)| {
            *a != 0.0 || *b != 0.0 || *c != 0.0
        })
        .prop_map(|(a, b, c, d)| [a, b, c, d]);
    (
        prop_oneof![Just(Integrator::Rk4), Just(Integrator::Euler)],
        positive(),
        1u64..100_000,
        [
            non_negative(),
            non_negative(),
            non_negative(),
            non_negative(),
        ],
        positive(),
        prop::option::of(plane),
        (0usize..4).prop_flat_map(|r| (Just(r), prop::collection::vec(vec3(), r * r * r))),
        prop::collection::vec(vec3(), 512),
        prop::collection::vec(vec3(), 512),
    )
        .prop_map(
            |(integrator, dt, every, [ke, de, kc, dc], mass, plane, (r, field), x, v)| World {
                integrator,
                dt,
                every,
                k_elastic: ke,
                d_elastic: de,
                k_collision: kc,
                d_collision: dc,
                mass,
                plane,
                resolution: r,
                field,
                positions: x,
                velocities: v,
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn a_written_world_reads_back_identical(w in world()) {
        let text = w.to_text();
        let back = parse_world(&text, Path::new("roundtrip.w")).map_err(|e| {
            TestCaseError::fail(format!("{e}"))
        })?;
        prop_assert_eq!(back, w);
    }

    #[test]
    fn a_printed_scene_loads_back_identical(
        which in 0usize..5,
        dt in positive(),
        gravity in [finite(), finite(), finite()],
        drag in non_negative(),
        mass in positive(),
        origin in [finite(), finite(), finite()],
        ks in non_negative(),
    ) {
        let (_, make) = hooke_scene::builtin::BUILTINS[which];
        let mut spec: SceneSpec = make();
        spec.simulation.dt = Positive::of(dt);
        spec.simulation.gravity = gravity.map(Finite::of);
        spec.simulation.drag = NonNegative::of(drag);
        for body in &mut spec.bodies {
            body.mass = Some(Positive::of(mass));
            body.origin = origin.map(Finite::of);
            if let Some(p) = &mut body.springs.structural {
                p.ks = NonNegative::of(ks);
            }
        }
        let text = hooke_scene::to_toml(&spec);
        let back = hooke_scene::parse_scene(&text, "roundtrip.toml")
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(back, spec);
    }
}
