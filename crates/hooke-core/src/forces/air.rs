//! Air: pressure drag and lift on a body's triangles, in a wind that may gust
//! (docs/physics.md §1, "Air").
//!
//! Air of density `ρ` moves with the wind velocity `w(t)`; a triangle of area `A`, unit
//! normal `n` and mean vertex velocity `v` sees `u = v − w`, and feels
//!
//! * drag `F_d = −½ ρ C_d A |u| (u·n) n` (pressure drag, normal to the surface), and
//! * lift `F_l = −½ ρ C_l A (u·n) (|u|² n − (u·n) u) / |u|` (perpendicular to `u`, in the
//!   plane of `u` and `n`; zero face-on and edge-on),
//!
//! each split equally over its three particles, nothing when `|u| < 1e-12`. Both are
//! unchanged when `n` flips, so triangle winding does not matter. The forces are part of the
//! force evaluation, so every Runge–Kutta stage sees them at its own state and time; the
//! implicit integrator takes them at the step's start and leaves them out of its Jacobian.
//!
//! The evaluation is deterministic on any thread count: each triangle's force is computed on
//! its own, then each particle adds its triangles' thirds in ascending triangle order.

use crate::parallel;
use crate::particles::Vec3;

/// Relative speeds below this (m/s) give no air force: the direction of `u` is undefined.
pub const STILL_AIR_SPEED: f64 = 1e-12;

/// Air density at sea level and 15 °C, kg/m³: the usual default.
pub const SEA_LEVEL_DENSITY: f64 = 1.225;

/// The air a system moves in.
///
/// ```
/// use hooke_core::{Air, Gust, Vec3};
/// let air = Air {
///     density: 1.225,
///     wind: Vec3::new(5.0, 0.0, 0.0),
///     gust: Some(Gust { amplitude: Vec3::new(2.0, 0.0, 1.0), period: 2.0 }),
/// };
/// // A quarter period in, the gust is at its height.
/// assert!((air.wind_at(0.5) - Vec3::new(7.0, 0.0, 1.0)).norm() < 1e-12);
/// assert_eq!(air.wind_at(0.0), Vec3::new(5.0, 0.0, 0.0));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Air {
    /// Density `ρ` in kg/m³.
    pub density: f64,
    /// The steady wind velocity in m/s.
    pub wind: Vec3,
    /// A periodic gust on top of the steady wind, if any.
    pub gust: Option<Gust>,
}

/// A smooth, deterministic variation of the wind: `amplitude · sin(2π t / period)` added to
/// the steady wind, so the mean wind stays the steady one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gust {
    /// The largest change of the wind velocity, m/s.
    pub amplitude: Vec3,
    /// Seconds from one gust to the next.
    pub period: f64,
}

impl Air {
    /// The wind velocity at simulated time `t` seconds.
    pub fn wind_at(&self, t: f64) -> Vec3 {
        match self.gust {
            Some(g) if g.period > 0.0 => {
                // sin(2π t/T), with the phase reduced first so long runs keep full precision.
                let phase = (t / g.period).fract();
                self.wind + g.amplitude * (std::f64::consts::TAU * phase).sin()
            }
            _ => self.wind,
        }
    }
}

/// A body's triangles as the air sees them, with its coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct AeroSurface {
    /// Triangles as indices into the simulation's particles.
    pub triangles: Vec<[u32; 3]>,
    /// Drag coefficient `C_d` (1 for a flat plate face-on is the usual choice).
    pub drag: f64,
    /// Lift coefficient `C_l`.
    pub lift: f64,
}

/// The air force on one triangle with corners `x` and corner velocities `v`, in air of
/// `density` moving at `wind`, with coefficients `drag` and `lift`: the total, of which each
/// corner takes a third.
///
/// ```
/// use hooke_core::{Vec3, forces::air::triangle_force};
/// // A unit right triangle in the x-z plane falling face-on at 2 m/s in still air.
/// let x = [Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)];
/// let v = [Vec3::new(0.0, -2.0, 0.0); 3];
/// let f = triangle_force(1.2, 1.0, 0.0, &x, &v, &Vec3::zeros());
/// // ½ ρ C_d A |u|² = ½ · 1.2 · 1 · 0.5 · 4, upward.
/// assert!((f - Vec3::new(0.0, 1.2, 0.0)).norm() < 1e-12);
/// ```
#[inline]
pub fn triangle_force(
    density: f64,
    drag: f64,
    lift: f64,
    x: &[Vec3; 3],
    v: &[Vec3; 3],
    wind: &Vec3,
) -> Vec3 {
    let cross = (x[1] - x[0]).cross(&(x[2] - x[0]));
    let twice_area = cross.norm();
    let u = (v[0] + v[1] + v[2]) * (1.0 / 3.0) - wind;
    let speed = u.norm();
    // A degenerate triangle has no normal; still air has no direction.
    if !(twice_area > 0.0 && speed >= STILL_AIR_SPEED) {
        return Vec3::zeros();
    }
    let n = cross * (1.0 / twice_area);
    let un = u.dot(&n);
    let q = 0.5 * density * (0.5 * twice_area);
    let f = n * (-q * drag * speed * un);
    if lift == 0.0 {
        return f;
    }
    f + (n * (speed * speed) - u * un) * (-q * lift * un / speed)
}

/// The air forces of a model, evaluated into per-particle buffers kept between steps.
#[derive(Clone, Debug, Default)]
pub struct AirForces {
    /// Every aero surface's triangles, and the index of its surface.
    triangles: Vec<([u32; 3], u32)>,
    /// A third of each triangle's force, from the last evaluation.
    thirds: Vec<Vec3>,
    /// For particle `p`, `incident[start[p]..start[p + 1]]` are its triangles, ascending.
    start: Vec<u32>,
    incident: Vec<u32>,
    /// The air force on each particle from the last evaluation.
    forces: Vec<Vec3>,
    /// The particle count and surfaces' triangle count the incidences were built for.
    built_for: (usize, usize),
}

impl AirForces {
    /// Builds the incidences of `model`'s aero surfaces over `particles` particles, unless
    /// they already fit.
    pub(crate) fn ensure(&mut self, aero: &[AeroSurface], particles: usize) {
        let count: usize = aero.iter().map(|s| s.triangles.len()).sum();
        if self.built_for == (particles, count) && self.start.len() == particles + 1 {
            return;
        }
        self.triangles = aero
            .iter()
            .enumerate()
            .flat_map(|(s, surface)| surface.triangles.iter().map(move |&t| (t, s as u32)))
            .collect();
        // A counting sort of (particle, triangle) pairs: ascending triangles per particle.
        let mut start = vec![0u32; particles + 1];
        for (t, _) in &self.triangles {
            for &p in t {
                start[p as usize + 1] += 1;
            }
        }
        for p in 0..particles {
            start[p + 1] += start[p];
        }
        let mut next = start.clone();
        let mut incident = vec![0u32; start[particles] as usize];
        for (k, (t, _)) in self.triangles.iter().enumerate() {
            for &p in t {
                incident[next[p as usize] as usize] = k as u32;
                next[p as usize] += 1;
            }
        }
        self.start = start;
        self.incident = incident;
        self.thirds = vec![Vec3::zeros(); self.triangles.len()];
        self.forces = vec![Vec3::zeros(); particles];
        self.built_for = (particles, count);
    }

    /// The air force on every particle at state `(x, v)` and time `t`, or an empty slice
    /// when the model has no air (so callers add nothing, and results without air keep
    /// their bits).
    pub(crate) fn evaluate(
        &mut self,
        air: Option<&Air>,
        aero: &[AeroSurface],
        x: &[Vec3],
        v: &[Vec3],
        t: f64,
    ) -> &[Vec3] {
        let Some(air) = air else {
            return &[];
        };
        if self.triangles.is_empty() {
            return &[];
        }
        let wind = air.wind_at(t);
        let triangles = &self.triangles;
        parallel::for_each(&mut self.thirds, |k, third| {
            let ([a, b, c], s) = triangles[k];
            let (a, b, c) = (a as usize, b as usize, c as usize);
            let surface = &aero[s as usize];
            let f = triangle_force(
                air.density,
                surface.drag,
                surface.lift,
                &[x[a], x[b], x[c]],
                &[v[a], v[b], v[c]],
                &wind,
            );
            *third = f * (1.0 / 3.0);
        });
        let (start, incident, thirds) = (&self.start, &self.incident, &self.thirds);
        parallel::for_each(&mut self.forces, |p, f| {
            let mine = &incident[start[p] as usize..start[p + 1] as usize];
            *f = mine
                .iter()
                .fold(Vec3::zeros(), |sum, &k| sum + thirds[k as usize]);
        });
        &self.forces
    }
}
