//! The built-in scenes: the course document's five, a cloth pile for self-contact and a flag
//! in the wind, defined in code.
//!
//! Each is also shipped as `assets/scenes/<name>.toml` (written by `hooke scene NAME`), and a
//! test checks that every file equals its built-in. Parameters were chosen so that each scene
//! is stable with its own integrator and step (see `hooke check`), shows its point within a
//! few seconds, and runs in about a second in a release build.

use crate::spec::*;
use hooke_core::Integrator;

fn f3(v: [f64; 3]) -> [Finite; 3] {
    v.map(Finite::of)
}

fn params(ks: f64, kd: f64) -> Option<SpringParams> {
    Some(SpringParams {
        ks: NonNegative::of(ks),
        kd: NonNegative::of(kd),
    })
}

fn sim(integrator: Integrator, dt: f64, duration: f64, every: u64, drag: f64) -> SimulationSpec {
    SimulationSpec {
        integrator: IntegratorName(integrator),
        dt: Positive::of(dt),
        duration: Some(Positive::of(duration)),
        steps: None,
        every,
        gravity: f3([0.0, -9.81, 0.0]),
        drag: NonNegative::of(drag),
        mass_drag: NonNegative::of(0.0),
        tolerance: None,
        iterations: None,
        air: None,
    }
}

fn body(
    name: &str,
    mass: f64,
    origin: [f64; 3],
    shape: ShapeSpec,
    springs: SpringsSpec,
) -> BodySpec {
    BodySpec {
        name: name.into(),
        mass: Some(Positive::of(mass)),
        origin: f3(origin),
        rotate: f3([0.0; 3]),
        velocity: f3([0.0; 3]),
        pins: Default::default(),
        positions: None,
        velocities: None,
        shape,
        springs,
        material: None,
        pin_motion: None,
        thickness: None,
        self_collision: None,
        friction: None,
        aero: None,
    }
}

/// A shipped mesh (`builtin:…`) where it was modelled, with `response`.
fn shipped_mesh(path: &str, response: ResponseSpec) -> ColliderSpec {
    ColliderSpec {
        shape: ColliderShapeSpec::Mesh {
            path: path.into(),
            translate: f3([0.0; 3]),
            rotate: f3([0.0; 3]),
            scale: [Positive::of(1.0); 3],
        },
        response,
        motion: None,
    }
}

fn ground(cr: f64, friction: f64) -> ColliderSpec {
    ColliderSpec {
        shape: ColliderShapeSpec::Ground {
            height: Finite::of(0.0),
        },
        response: ResponseSpec::Restitution {
            cr: Fraction::of(cr),
            friction: NonNegative::of(friction),
        },
        motion: None,
    }
}

/// Stiffness of `single-spring`, N/m; with its 1 kg mass `ω = √(k/m) = 10 rad/s`.
pub const SINGLE_SPRING_KS: f64 = 100.0;
/// Damping of `single-spring`: damping ratio `kd / (2 √(k m)) = 0.05`, so the 0.4 m swing
/// decays below 0.1 mm within the 20 s run.
pub const SINGLE_SPRING_KD: f64 = 1.0;

/// A 1 kg mass on a 1 m spring from a fixed anchor at `(0, 2, 0)`, released 0.5 m stretched;
/// it oscillates about `rest + m g / k` below the anchor and settles there.
pub fn single_spring() -> SceneSpec {
    let mut b = body(
        "mass",
        1.0,
        [0.0, 2.0, 0.0],
        ShapeSpec::Points {
            positions: vec![f3([0.0, 0.0, 0.0]), f3([0.0, -1.5, 0.0])],
        },
        SpringsSpec::default(),
    );
    b.pins = vec![0].into();
    b.springs.pairs = vec![PairSpec {
        i: 0,
        j: 1,
        ks: NonNegative::of(SINGLE_SPRING_KS),
        kd: NonNegative::of(SINGLE_SPRING_KD),
        rest: Some(NonNegative::of(1.0)),
    }];
    SceneSpec {
        name: "single-spring".into(),
        description: "a 1 kg mass on a 100 N/m spring, released 0.5 m stretched; settles at rest length + mg/k".into(),
        simulation: sim(Integrator::Symplectic, 1e-3, 20.0, 20, 0.0),
        bodies: vec![b],
        colliders: Vec::new(),
        force_field: None,
    }
}

/// Particles of `chain`, the anchor included.
pub const CHAIN_COUNT: usize = 12;
/// Mass of each chain particle, kg.
pub const CHAIN_MASS: f64 = 0.05;
/// Stiffness of each chain link, N/m.
pub const CHAIN_KS: f64 = 2000.0;

/// Twelve 50 g masses in a horizontal line from a fixed anchor, released: a chain pendulum
/// that swings, whips, and comes to hang straight (light drag takes out the swing).
pub fn chain() -> SceneSpec {
    let mut b = body(
        "chain",
        CHAIN_MASS,
        [0.0, 2.2, 0.0],
        ShapeSpec::Chain {
            count: CHAIN_COUNT,
            spacing: Positive::of(0.15),
        },
        SpringsSpec {
            structural: params(CHAIN_KS, 0.2),
            ..SpringsSpec::default()
        },
    );
    b.pins = vec![0].into();
    SceneSpec {
        name: "chain".into(),
        description:
            "a chain pendulum of 12 masses released horizontal; swings and comes to hang straight"
                .into(),
        simulation: sim(Integrator::Symplectic, 2e-4, 12.0, 100, 0.03),
        bodies: vec![b],
        colliders: vec![ground(0.3, 0.2)],
        force_field: None,
    }
}

/// An 8×8×8 jelly cube of side 0.5 m and 1 kg, tilted and dropped on the ground, which it
/// bounces off (restitution, as in the course) before settling without losing its shape.
pub fn jello_cube() -> SceneSpec {
    let mut b = body(
        "jelly",
        1.0 / 512.0,
        [-0.15, 0.9, -0.25],
        ShapeSpec::Lattice {
            size: [8, 8, 8],
            spacing: Positive::of(0.5 / 7.0),
        },
        SpringsSpec {
            structural: params(300.0, 0.3),
            shear: params(300.0, 0.3),
            bend: params(150.0, 0.3),
            pairs: Vec::new(),
        },
    );
    b.rotate = f3([30.0, 20.0, 35.0]);
    SceneSpec {
        name: "jello-cube".into(),
        description:
            "an 8x8x8 jelly cube dropped tilted onto the ground; bounces, settles, keeps its shape"
                .into(),
        simulation: sim(Integrator::Symplectic, 2.5e-4, 3.0, 40, 0.0),
        bodies: vec![b],
        colliders: vec![ground(0.5, 0.3)],
        force_field: None,
    }
}

/// A 25×25 cloth of 1 m² and 0.5 kg, horizontal, pinned at its two corners on the x = 0
/// edge: it swings down and settles into a drape.
pub fn hanging_cloth() -> SceneSpec {
    let n = 25;
    let mut b = body(
        "cloth",
        0.5 / (n * n) as f64,
        [-0.5, 2.0, -0.5],
        ShapeSpec::Grid {
            size: [n, n],
            spacing: Positive::of(1.0 / (n - 1) as f64),
        },
        SpringsSpec {
            structural: params(400.0, 0.02),
            shear: params(200.0, 0.02),
            bend: params(20.0, 0.005),
            pairs: Vec::new(),
        },
    );
    b.pins = vec![0, n - 1].into();
    SceneSpec {
        name: "hanging-cloth".into(),
        description:
            "a 25x25 cloth pinned at two corners, released flat; swings and settles into a drape"
                .into(),
        simulation: sim(Integrator::Symplectic, 2.5e-4, 6.0, 40, 0.002),
        bodies: vec![b],
        colliders: vec![ground(0.2, 0.5)],
        force_field: None,
    }
}

/// An `n × n` cloth of `side` metres square and `kg` in all, its corner at `origin`, with
/// the table cloths' structural (300 N/m) and shear (150 N/m) springs and `bend` as
/// `(ks, kd)`.
fn square_cloth(n: usize, side: f64, kg: f64, origin: [f64; 3], bend: (f64, f64)) -> BodySpec {
    body(
        "cloth",
        kg / (n * n) as f64,
        origin,
        ShapeSpec::Grid {
            size: [n, n],
            spacing: Positive::of(side / (n - 1) as f64),
        },
        SpringsSpec {
            structural: params(300.0, 0.02),
            shear: params(150.0, 0.02),
            bend: params(bend.0, bend.1),
            pairs: Vec::new(),
        },
    )
}

/// A 32×32 cloth of 1.6 m square dropped flat onto the round table (`builtin:table.obj`, top
/// radius 0.6 m at y = 1): particles touching the table stick, the edges hang down.
pub fn cloth_table() -> SceneSpec {
    let side = 1.6;
    let b = square_cloth(
        32,
        side,
        0.4,
        [-side / 2.0, 1.3, -side / 2.0],
        (15.0, 0.005),
    );
    SceneSpec {
        name: "cloth-table".into(),
        description:
            "a 32x32 cloth dropped onto a round table; the middle sticks to the top, the edges hang"
                .into(),
        simulation: sim(Integrator::Symplectic, 2.5e-4, 3.0, 40, 0.002),
        bodies: vec![b],
        colliders: vec![
            ground(0.2, 0.5),
            shipped_mesh("builtin:table.obj", ResponseSpec::Stick),
        ],
        force_field: None,
    }
}

/// A 32×32 cloth of 1.2 m square and 0.3 kg, held upright and a little tilted with its
/// lower edge just above the ground, then released: it buckles, folds over onto itself and
/// settles into a pile, the case self-collision exists for.
pub fn cloth_pile() -> SceneSpec {
    let side = 1.2;
    // Rotated about x, the grid's local z runs up; its lowest row starts 2 cm up.
    let mut b = square_cloth(32, side, 0.3, [-side / 2.0, 0.02, 0.0], (2.0, 0.002));
    b.rotate = f3([-80.0, 0.0, 15.0]);
    SceneSpec {
        name: "cloth-pile".into(),
        description: "a 32x32 cloth released upright on the ground; folds onto itself into a pile"
            .into(),
        simulation: sim(Integrator::Symplectic, 2.5e-4, 3.0, 40, 0.002),
        bodies: vec![b],
        colliders: vec![ground(0.1, 0.6)],
        force_field: None,
    }
}

/// Radius of the flag's pole, metres.
pub const POLE_RADIUS: f64 = 0.03;

/// A 1.5 m × 1 m flag (30 × 20 particles, 0.22 kg) pinned along its hoist to a pole, in a
/// 6 m/s wind along +x with gusts that also swing it sideways: it streams out from the pole
/// and flutters. Air acts through drag and a little lift on its triangles.
pub fn flag() -> SceneSpec {
    let (fly, hoist) = (30, 20);
    let spacing = 1.5 / (fly - 1) as f64;
    let mut b = body(
        "flag",
        0.22 / (fly * hoist) as f64,
        // The hoist starts 1 cm off the pole, 2 m up.
        [POLE_RADIUS + 0.01, 2.0, 0.0],
        ShapeSpec::Grid {
            size: [fly, hoist],
            spacing: Positive::of(spacing),
        },
        SpringsSpec {
            structural: params(300.0, 0.02),
            shear: params(150.0, 0.02),
            bend: params(1.0, 0.002),
            pairs: Vec::new(),
        },
    );
    // Rotated about x, the grid's local z runs up: particles 0..hoist are the hoist.
    b.rotate = f3([-90.0, 0.0, 0.0]);
    b.pins = (0..hoist).collect::<Vec<_>>().into();
    b.aero = Some(AeroSpec {
        drag: NonNegative::of(1.0),
        lift: Finite::of(0.3),
    });
    let mut simulation = sim(Integrator::Symplectic, 2.5e-4, 5.0, 120, 0.0);
    simulation.air = Some(AirSpec {
        density: Positive::of(hooke_core::forces::air::SEA_LEVEL_DENSITY),
        wind: f3([6.0, 0.0, 0.0]),
        gust: Some(GustSpec {
            amplitude: f3([2.0, 0.0, 2.5]),
            period: Positive::of(1.7),
        }),
    });
    let pole_top = 3.1;
    SceneSpec {
        name: "flag".into(),
        description: "a 1.5 x 1 m flag on a pole in a gusting 6 m/s wind; streams out and flutters"
            .into(),
        simulation,
        bodies: vec![b],
        colliders: vec![
            ground(0.2, 0.5),
            ColliderSpec {
                shape: ColliderShapeSpec::Cylinder {
                    center: f3([0.0, pole_top, 0.0]),
                    radius: Positive::of(POLE_RADIUS),
                    thickness: Positive::of(pole_top),
                },
                response: ResponseSpec::Restitution {
                    cr: Fraction::of(0.0),
                    friction: NonNegative::of(0.3),
                },
                motion: None,
            },
        ],
        force_field: None,
    }
}

/// Side of `tablecloth`'s cloth, metres, and its particles per side.
pub const TABLECLOTH: (f64, usize) = (1.6, 36);

/// A cotton tablecloth given as a material (`preset = "cotton"`: 150 g/m², B = 5 µN·m,
/// docs/physics.md §1.1) of 1.6 m square, 36×36, dropped 10 cm onto the square table
/// (`builtin:square-table.obj`, side 1 m, top at y = 0.9), in still air, with Coulomb
/// friction 0.5 on the top: it hangs in folds, its corners lowest.
pub fn tablecloth() -> SceneSpec {
    let (side, n) = TABLECLOTH;
    let mut cloth = body(
        "cloth",
        1.0,
        [-side / 2.0, 1.0, -side / 2.0],
        ShapeSpec::Grid {
            size: [n, n],
            spacing: Positive::of(side / (n - 1) as f64),
        },
        SpringsSpec::default(),
    );
    cloth.mass = None;
    cloth.material = Some(MaterialSpec {
        preset: Some("cotton".into()),
        ..MaterialSpec::default()
    });
    let mut simulation = sim(Integrator::Symplectic, 2.5e-4, 3.0, 40, 0.0);
    simulation.air = Some(AirSpec {
        density: Positive::of(hooke_core::forces::air::SEA_LEVEL_DENSITY),
        wind: f3([0.0; 3]),
        gust: None,
    });
    SceneSpec {
        name: "tablecloth".into(),
        description: "a 36x36 cotton tablecloth (a material in SI units) dropped onto the square table; hangs in folds"
            .into(),
        simulation,
        bodies: vec![cloth],
        colliders: vec![
            ground(0.0, 0.5),
            shipped_mesh(
                "builtin:square-table.obj",
                ResponseSpec::Restitution {
                    cr: Fraction::of(0.0),
                    friction: NonNegative::of(0.5),
                },
            ),
        ],
        force_field: None,
    }
}

/// `hanging-cloth` with a moving collider (docs/physics.md §2.1): a puck (a cylinder 0.3 m
/// across and 0.4 m tall, Coulomb friction 0.3) keyed through the hanging cloth at 0.7 m/s
/// from 2 s to 4 s, turning a quarter about the vertical on the way; the cloth is pushed
/// aside and swings back.
pub fn puck_sweep() -> SceneSpec {
    let mut spec = hanging_cloth();
    spec.name = "puck-sweep".into();
    spec.description =
        "the hanging cloth with a puck keyed through it (a moving collider); pushed aside, it swings back as the puck moves on"
            .into();
    spec.simulation.duration = Some(Positive::of(5.0));
    let key = |t: f64, x: f64, turn: f64| KeySpec {
        t: Finite::of(t),
        translate: f3([x, 0.0, 0.0]),
        rotate: Some(f3([0.0, turn, 0.0])),
    };
    spec.colliders.push(ColliderSpec {
        shape: ColliderShapeSpec::Cylinder {
            center: f3([-1.5, 1.7, 0.0]),
            radius: Positive::of(0.15),
            thickness: Positive::of(0.4),
        },
        response: ResponseSpec::Restitution {
            cr: Fraction::of(0.0),
            friction: NonNegative::of(0.3),
        },
        motion: Some(MotionSpec::of_keys(vec![
            key(2.0, 0.0, 0.0),
            key(4.0, 2.5, 90.0),
        ])),
    });
    spec
}

/// Makes a built-in scene.
pub type Maker = fn() -> SceneSpec;

/// The built-in scenes by name: the course document's five, then the contact scene, the
/// air scene, the material tablecloth and the moving puck.
pub const BUILTINS: [(&str, Maker); 9] = [
    ("single-spring", single_spring),
    ("chain", chain),
    ("jello-cube", jello_cube),
    ("hanging-cloth", hanging_cloth),
    ("cloth-table", cloth_table),
    ("cloth-pile", cloth_pile),
    ("flag", flag),
    ("tablecloth", tablecloth),
    ("puck-sweep", puck_sweep),
];

/// The built-in scene called `name`.
pub fn builtin(name: &str) -> Option<SceneSpec> {
    BUILTINS.iter().find(|(n, _)| *n == name).map(|(_, f)| f())
}

/// The analytic cylinder of the built-in round table (the course's tabletop): the shape
/// [`crate::TableOverride::Cylinder`] puts in place of a scene's table.
pub fn round_table_cylinder() -> ColliderShapeSpec {
    use hooke_collide::table::round;
    ColliderShapeSpec::Cylinder {
        center: [Finite::of(0.0), Finite::of(round::TOP_Y), Finite::of(0.0)],
        radius: Positive::of(round::TOP_RADIUS),
        thickness: Positive::of(round::TOP_THICKNESS),
    }
}
