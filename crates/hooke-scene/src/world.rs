//! Jello worlds: the `.w` text format of the USC CSCI 520 jello cube (docs/physics.md §5).
//!
//! ```text
//! RK4 | Euler                    integrator (any case)
//! dt n                           step size; every n-th step is a frame
//! kElastic dElastic kCollision dCollision
//! mass                           of each of the 512 points
//! 0 | 1                          inclined plane present?
//! a b c d                        only when present
//! r                              force-field resolution, then r³ lines "fx fy fz"
//! 512 lines "x y z"              positions, point (i, j, k) at index i*64 + j*8 + k
//! 512 lines "vx vy vz"           velocities, same order
//! ```
//!
//! The course reads these files with `fscanf`, so line breaks are just white space: the reader
//! here takes whitespace-separated tokens too, and reports each problem with the line of the
//! token where it went wrong and what was expected there. The writer prints numbers in their
//! shortest round-trip form ([`hooke_core::Num`]; the course writes `%lf`, six decimals, and
//! its `fscanf` reads scientific form too), so write → read is exact.

use crate::spec::*;
use hooke_core::Num;
use hooke_core::{Integrator, Vec3};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Points per axis of the jello cube.
pub const SIDE: usize = 8;
/// Points of the jello cube.
pub const POINTS: usize = SIDE * SIDE * SIDE;
/// Spacing of the undeformed cube of side 1 (docs/physics.md §5: rest lengths come from it).
pub const SPACING: f64 = 1.0 / 7.0;
/// Steps run when neither the command line nor the world says how long to run.
pub const DEFAULT_STEPS: u64 = 1000;
/// The largest force-field resolution accepted (`r³` vectors must fit in memory).
pub const MAX_RESOLUTION: usize = 400;

/// A jello world.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    /// `rk4` or `euler`.
    pub integrator: Integrator,
    /// Step size in seconds.
    pub dt: f64,
    /// A frame every this many steps.
    pub every: u64,
    /// Spring stiffness, N/m.
    pub k_elastic: f64,
    /// Spring damping, N·s/m.
    pub d_elastic: f64,
    /// Collision penalty stiffness, N/m.
    pub k_collision: f64,
    /// Collision penalty damping, N·s/m.
    pub d_collision: f64,
    /// Mass of each point, kg.
    pub mass: f64,
    /// The inclined plane `a x + b y + c z + d = 0`, if present.
    pub plane: Option<[f64; 4]>,
    /// Force-field resolution `r` (0: no field).
    pub resolution: usize,
    /// `r³` force vectors in file order.
    pub field: Vec<Vec3>,
    /// 512 positions, index `i*64 + j*8 + k`.
    pub positions: Vec<Vec3>,
    /// 512 velocities.
    pub velocities: Vec<Vec3>,
}

/// A `.w` file that cannot be read, with where and why.
#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    /// The file could not be read.
    #[error("cannot read world {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The text does not follow the format.
    #[error("{path}:{line}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was expected and what was found.
        message: String,
    },
}

/// The words of a world, with their lines, read one at a time: a world with a large force
/// field is never held as a list of its words (which would take several times its size).
struct Tokens<'a> {
    path: &'a Path,
    words: std::iter::Peekable<Box<dyn Iterator<Item = (usize, &'a str)> + 'a>>,
    /// The line of the word read last.
    line: usize,
    last_line: usize,
}

/// Characters of a word echoed in an error.
const EXCERPT_CHARS: usize = 40;

/// At most [`EXCERPT_CHARS`] characters of `word`, with `…` where it was cut.
fn excerpt(word: &str) -> String {
    hooke_core::excerpt(word, EXCERPT_CHARS)
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str, path: &'a Path) -> Self {
        let words: Box<dyn Iterator<Item = (usize, &'a str)> + 'a> = Box::new(
            text.lines()
                .enumerate()
                .flat_map(|(n, line)| line.split_whitespace().map(move |w| (n + 1, w))),
        );
        Self {
            path,
            words: words.peekable(),
            line: 1,
            last_line: text.lines().count().max(1),
        }
    }

    fn fail(&self, line: usize, message: String) -> WorldError {
        WorldError::Format {
            path: self.path.to_path_buf(),
            line,
            message,
        }
    }

    fn word(&mut self, what: &str) -> Result<(usize, &'a str), WorldError> {
        match self.words.next() {
            Some(w) => {
                self.line = w.0;
                Ok(w)
            }
            None => Err(self.fail(
                self.last_line,
                format!("unexpected end of file: expected {what}"),
            )),
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, WorldError> {
        let (line, w) = self.word(what)?;
        match w.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(_) => Err(self.fail(
                line,
                format!("expected {what} as a finite number, found '{}'", excerpt(w)),
            )),
            Err(_) => Err(self.fail(
                line,
                format!("expected {what} (a number), found '{}'", excerpt(w)),
            )),
        }
    }

    fn checked(
        &mut self,
        what: &str,
        ok: impl Fn(f64) -> bool,
        rule: &str,
    ) -> Result<f64, WorldError> {
        let line = self.words.peek().map_or(self.last_line, |w| w.0);
        let x = self.number(what)?;
        if ok(x) {
            Ok(x)
        } else {
            Err(self.fail(line, format!("expected {what} {rule}, found {}", Num(x))))
        }
    }

    fn integer(&mut self, what: &str, max: u64) -> Result<u64, WorldError> {
        let (line, w) = self.word(what)?;
        match w.parse::<i64>() {
            Ok(n) if n >= 0 && n as u64 <= max => Ok(n as u64),
            Ok(n) => Err(self.fail(line, format!("expected {what} from 0 to {max}, found {n}"))),
            Err(_) => Err(self.fail(
                line,
                format!("expected {what} (a whole number), found '{}'", excerpt(w)),
            )),
        }
    }

    fn vectors(&mut self, count: usize, what: &str) -> Result<Vec<Vec3>, WorldError> {
        (0..count)
            .map(|k| {
                let name = format!("{what} {k} of {count}");
                Ok(Vec3::new(
                    self.number(&format!("x of {name}"))?,
                    self.number(&format!("y of {name}"))?,
                    self.number(&format!("z of {name}"))?,
                ))
            })
            .collect()
    }
}

/// Reads a `.w` file.
pub fn load_world(path: &Path) -> Result<World, WorldError> {
    let text = hooke_core::text::read_text(path).map_err(|source| WorldError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_world(&text, path)
}

/// Parses `.w` text; `path` names it in errors.
pub fn parse_world(text: &str, path: &Path) -> Result<World, WorldError> {
    let mut t = Tokens::new(text, path);
    let (line, name) = t.word("the integrator (RK4 or Euler)")?;
    let integrator = match name.to_ascii_lowercase().as_str() {
        "rk4" => Integrator::Rk4,
        "euler" => Integrator::Euler,
        _ => {
            return Err(t.fail(
                line,
                format!("expected the integrator RK4 or Euler, found '{name}'"),
            ));
        }
    };
    let dt = t.checked("the step size dt", |x| x > 0.0, "> 0")?;
    let every = t.integer("the frame cadence n", u32::MAX as u64)?;
    if every == 0 {
        return Err(t.fail(t.line, "expected the frame cadence n >= 1, found 0".into()));
    }
    let non_negative = |x: f64| x >= 0.0;
    let k_elastic = t.checked("kElastic", non_negative, ">= 0")?;
    let d_elastic = t.checked("dElastic", non_negative, ">= 0")?;
    let k_collision = t.checked("kCollision", non_negative, ">= 0")?;
    let d_collision = t.checked("dCollision", non_negative, ">= 0")?;
    let mass = t.checked("the point mass", |x| x > 0.0, "> 0")?;
    let plane = match t.integer("the inclined-plane flag (0 or 1)", 1)? {
        1 => {
            let c = [
                t.number("plane a")?,
                t.number("plane b")?,
                t.number("plane c")?,
                t.number("plane d")?,
            ];
            if c[..3].iter().all(|x| *x == 0.0) {
                return Err(t.fail(t.line, "expected a plane: a, b and c are all zero".into()));
            }
            Some(c)
        }
        _ => None,
    };
    let resolution = t.integer("the force-field resolution r", MAX_RESOLUTION as u64)? as usize;
    let field = t.vectors(resolution.pow(3), "force-field vector")?;
    let positions = t.vectors(POINTS, "position")?;
    let velocities = t.vectors(POINTS, "velocity")?;
    if let Some(&(line, w)) = t.words.peek() {
        return Err(t.fail(
            line,
            format!(
                "expected the end of the file after 512 velocities, found '{}'",
                excerpt(w)
            ),
        ));
    }
    Ok(World {
        integrator,
        dt,
        every,
        k_elastic,
        d_elastic,
        k_collision,
        d_collision,
        mass,
        plane,
        resolution,
        field,
        positions,
        velocities,
    })
}

/// Why a scene cannot be saved as a jello world.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct NotAWorld(String);

/// A world value that a scene cannot hold (a [`World`] built in code, not read: the reader
/// refuses these with the file's line).
#[derive(Debug, thiserror::Error)]
#[error("world value {key}: {message}")]
pub struct InvalidWorld {
    /// The `.w` name of the value, with its index for vectors (`positions[3]`).
    pub key: String,
    /// What was expected and found.
    pub message: String,
}

/// `checked(x)`, or the error naming `key`.
fn check<T>(
    key: impl Fn() -> String,
    x: f64,
    checked: fn(f64) -> Result<T, String>,
) -> Result<T, InvalidWorld> {
    checked(x).map_err(|message| InvalidWorld {
        key: key(),
        message,
    })
}

/// The vectors of `list` as finite triples, named `key[i]` when one is not.
fn finite_list(key: &str, list: &[Vec3]) -> Result<Vec<[Finite; 3]>, InvalidWorld> {
    list.iter()
        .enumerate()
        .map(|(i, v)| {
            let mut out = [Finite::of(0.0); 3];
            for (o, c) in out.iter_mut().zip(v.iter()) {
                *o = check(|| format!("{key}[{i}]"), *c, Finite::new)?;
            }
            Ok(out)
        })
        .collect()
}

impl World {
    /// The world as `.w` text.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let name = if self.integrator == Integrator::Rk4 {
            "RK4"
        } else {
            "Euler"
        };
        let _ = writeln!(s, "{name}");
        let _ = writeln!(s, "{} {}", Num(self.dt), self.every);
        let _ = writeln!(
            s,
            "{} {} {} {}",
            Num(self.k_elastic),
            Num(self.d_elastic),
            Num(self.k_collision),
            Num(self.d_collision)
        );
        let _ = writeln!(s, "{}", Num(self.mass));
        match self.plane {
            Some([a, b, c, d]) => {
                let _ = writeln!(s, "1\n{} {} {} {}", Num(a), Num(b), Num(c), Num(d));
            }
            None => s.push_str("0\n"),
        }
        let _ = writeln!(s, "{}", self.resolution);
        for v in self
            .field
            .iter()
            .chain(&self.positions)
            .chain(&self.velocities)
        {
            let _ = writeln!(s, "{} {} {}", Num(v.x), Num(v.y), Num(v.z));
        }
        s
    }

    /// The world as a scene: the 8×8×8 lattice with all three spring families, rest lengths
    /// from the undeformed cube, the box and the plane as penalty colliders, the force field,
    /// no gravity.
    pub fn to_scene(&self, name: &str) -> Result<SceneSpec, InvalidWorld> {
        let non_negative = |key: &'static str, x| check(|| key.to_string(), x, NonNegative::new);
        let positive = |key: &'static str, x| check(|| key.to_string(), x, Positive::new);
        let springs = Some(SpringParams {
            ks: non_negative("kElastic", self.k_elastic)?,
            kd: non_negative("dElastic", self.d_elastic)?,
        });
        let penalty = ResponseSpec::Penalty {
            kc: non_negative("kCollision", self.k_collision)?,
            dc: non_negative("dCollision", self.d_collision)?,
        };
        let mut colliders = vec![ColliderSpec {
            shape: ColliderShapeSpec::Box {
                min: [Finite::of(-2.0); 3],
                max: [Finite::of(2.0); 3],
            },
            response: penalty,
            motion: None,
        }];
        if let Some(c) = self.plane {
            let mut coefficients = [Finite::of(0.0); 4];
            for (k, (o, x)) in coefficients.iter_mut().zip(c).enumerate() {
                *o = check(|| format!("plane[{k}]"), x, Finite::new)?;
            }
            colliders.push(ColliderSpec {
                shape: ColliderShapeSpec::Plane { coefficients },
                response: penalty,
                motion: None,
            });
        }
        let field = finite_list("forceField", &self.field)?;
        Ok(SceneSpec {
            name: name.to_string(),
            description: format!("jello world '{name}'"),
            simulation: SimulationSpec {
                integrator: IntegratorName(self.integrator),
                dt: positive("dt", self.dt)?,
                duration: None,
                steps: Some(DEFAULT_STEPS),
                every: self.every,
                gravity: [Finite::of(0.0); 3],
                drag: NonNegative::of(0.0),
                mass_drag: NonNegative::of(0.0),
                tolerance: None,
                iterations: None,
                air: None,
            },
            bodies: vec![BodySpec {
                name: "jello".into(),
                mass: Some(positive("mass", self.mass)?),
                origin: [Finite::of(0.0); 3],
                rotate: [Finite::of(0.0); 3],
                velocity: [Finite::of(0.0); 3],
                pins: Default::default(),
                positions: Some(finite_list("positions", &self.positions)?),
                velocities: Some(finite_list("velocities", &self.velocities)?),
                shape: ShapeSpec::Lattice {
                    size: [SIDE; 3],
                    spacing: Positive::of(SPACING),
                },
                springs: SpringsSpec {
                    structural: springs,
                    shear: springs,
                    bend: springs,
                    pairs: Vec::new(),
                },
                // docs/physics.md §5: a world's jelly has SPEC's bare per-particle contacts.
                material: None,
                pin_motion: None,
                thickness: None,
                self_collision: None,
                friction: None,
                aero: None,
            }],
            colliders,
            force_field: (self.resolution > 0).then_some(ForceFieldSpec {
                resolution: self.resolution,
                values: field,
            }),
        })
    }

    /// The scene as a world, when it is one: a single 8×8×8 lattice of spacing 1/7 with equal
    /// parameters for all spring families, the `[-2, 2]^3` box and at most one plane as penalty
    /// colliders with equal parameters, no gravity, no drag, no pins, RK4 or Euler.
    pub fn from_scene(spec: &SceneSpec) -> Result<World, NotAWorld> {
        let no = |m: &str| Err(NotAWorld(m.to_string()));
        let sim = &spec.simulation;
        let integrator = sim.integrator.0;
        if !matches!(integrator, Integrator::Rk4 | Integrator::Euler) {
            return no("jello worlds know only the rk4 and euler integrators");
        }
        if sim.gravity.iter().any(|g| g.get() != 0.0) || sim.drag.get() != 0.0 {
            return no("jello worlds have no gravity and no drag (use the force field)");
        }
        if sim.air.is_some() {
            return no("jello worlds have no air (use the force field)");
        }
        let [body] = spec.bodies.as_slice() else {
            return no("a jello world has exactly one body");
        };
        if body.shape
            != (ShapeSpec::Lattice {
                size: [SIDE; 3],
                spacing: Positive::of(SPACING),
            })
        {
            return no("the body must be an 8x8x8 lattice of spacing 1/7");
        }
        let s = &body.springs;
        let (Some(p), true) = (
            s.structural,
            s.shear == s.structural && s.bend == s.structural && s.pairs.is_empty(),
        ) else {
            return no(
                "structural, shear and bend springs must all be present with the same ks and kd, and no explicit pairs",
            );
        };
        if !body.pins.is_empty() {
            return no("jello worlds have no pinned points");
        }
        let Some(mass) = body.mass.filter(|_| body.material.is_none()) else {
            return no("jello worlds give one mass per particle, not a material");
        };
        if body.thickness.is_some_and(|h| h.get() != 0.0) {
            return no("jello worlds have no contact thickness (bare per-particle contacts)");
        }
        let mut penalty = None;
        let mut has_box = false;
        let mut plane = None;
        for c in &spec.colliders {
            let ResponseSpec::Penalty { kc, dc } = c.response else {
                return no("jello colliders are penalty springs");
            };
            if c.motion.is_some() {
                return no("jello colliders do not move");
            }
            if penalty.is_some_and(|p| p != (kc.get(), dc.get())) {
                return no("all colliders must share kCollision and dCollision");
            }
            penalty = Some((kc.get(), dc.get()));
            match &c.shape {
                ColliderShapeSpec::Box { min, max }
                    if min.iter().all(|x| x.get() == -2.0)
                        && max.iter().all(|x| x.get() == 2.0)
                        && !has_box =>
                {
                    has_box = true
                }
                ColliderShapeSpec::Plane { coefficients } if plane.is_none() => {
                    plane = Some(coefficients.map(|x| x.get()))
                }
                _ => return no("colliders must be the [-2, 2]^3 box and at most one plane"),
            }
        }
        let Some((k_collision, d_collision)) = penalty.filter(|_| has_box) else {
            return no("a jello world needs the [-2, 2]^3 box collider");
        };
        let v3 = |v: &[Finite; 3]| Vec3::new(v[0].get(), v[1].get(), v[2].get());
        let positions = match &body.positions {
            Some(ps) => ps.iter().map(v3).collect(),
            None => {
                let r = body.rotate.map(|a| a.get().to_radians());
                let rot = nalgebra::Rotation3::from_euler_angles(r[0], r[1], r[2]);
                let lattice = crate::generators::Lattice { size: [SIDE; 3] };
                lattice
                    .positions(SPACING)
                    .iter()
                    .map(|p| v3(&body.origin) + rot * p)
                    .collect()
            }
        };
        let velocities = match &body.velocities {
            Some(vs) => vs.iter().map(v3).collect(),
            None => vec![v3(&body.velocity); POINTS],
        };
        let (resolution, field) = match &spec.force_field {
            Some(f) => (f.resolution, f.values.iter().map(v3).collect()),
            None => (0, Vec::new()),
        };
        Ok(World {
            integrator,
            dt: sim.dt.get(),
            every: sim.every,
            k_elastic: p.ks.get(),
            d_elastic: p.kd.get(),
            k_collision,
            d_collision,
            mass: mass.get(),
            plane,
            resolution,
            field,
            positions,
            velocities,
        })
    }
}
