//! Energy from nowhere (docs/physics.md §7): a run whose total energy grows far beyond what
//! anything outside the springs could have supplied is diverging, even while every value
//! is finite and every particle is near the origin. Such a run is stopped with a
//! [`Divergence`] instead of grinding on: a body started inside a collider, a contact
//! thickness larger than the gap, or a step beyond what the scheme can take make energy
//! grow by orders of magnitude, and each step of such a state costs far more than a sane one.
//!
//! The total energy `E` is kinetic plus potential (springs, gravity, penalty springs), so
//! gravity and the springs do no net work on it. What may raise it: the force field, the
//! air, the attachments, keyframed pins (pins held still do no work) and moving colliders.
//! Their work is summed by source from their power `Σ max(0, F·v)` sampled at each check,
//! times the time since the last (a pin's or a moving collider's `F` is what holds its
//! particles against their springs and weight); a moving collider's is also bounded in the
//! energy scale below, for the bounces a sampled power misses. A run is runaway when
//!
//! ```text
//! E − E(0) > 10 S + 2 W
//! ```
//!
//! with `W` that work and `S` the start's energy scale: its kinetic, spring and penalty
//! energy plus the weight of every free particle over the bodies' extent and a metre
//! (`M |g| (L + 1 m)`), and for each moving collider `M (2 u² + |g| D)`, with `u` its largest
//! speed and `D` the length of its path (a bounce off it and a lift by it), or 1 mJ at
//! least. Schemes that merely drift (symplectic Euler's
//! oscillating energy, explicit Euler's slow gain) stay far inside this bound over any run a
//! scene is meant for; a blow-up leaves it within a few hundredths of a second. Checked
//! every 10 ms of simulated time (every step when the step is longer), so the check costs a
//! fraction of a per cent of a run.

use crate::forces::air::AirForces;
use crate::integrator::Integrator;
use crate::model::Model;
use crate::model::motion::PinMotion;
use crate::particles::{Particles, Vec3};
use crate::simulation::divergence::Divergence;
use crate::simulation::stability::StabilityEstimate;
use crate::simulation::summary;

/// Simulated time between checks, seconds.
const CHECK_EVERY: f64 = 0.01;

/// How many times the start's energy scale a run may gain beyond what was supplied.
const GROWTH: f64 = 10.0;

/// The share of the start's energy scale (less the moving colliders' part) that a run of
/// an integrator that takes energy out ([`Integrator::dissipates`]) may gain beyond what was
/// supplied: rounding, and the iterations' leftover.
const DISSIPATIVE_SLACK: f64 = 0.01;

/// The watch over a run's energy.
#[derive(Clone, Debug)]
pub(crate) struct EnergyWatch {
    /// Whether it stops a runaway run.
    pub(crate) enabled: bool,
    /// Steps between checks.
    interval: u64,
    /// The energy at the start, joules.
    start: f64,
    /// The start's energy scale `S`, joules, and the part of it that bounds the moving
    /// colliders' work.
    scale: f64,
    carried: f64,
    /// The work supplied so far `W`, joules.
    supplied: f64,
    /// The same work by source, joules: what the message names.
    sources: Sources,
    /// The air's forces, evaluated at checks.
    air: AirForces,
}

/// The total energy of a state: kinetic plus potential.
fn energy(model: &Model, p: &Particles) -> f64 {
    summary::kinetic(p) + model.potential_energy(&p.mass, &p.x)
}

impl EnergyWatch {
    /// A watch over a run of `model` starting at `p`, stepped by `dt`.
    pub(crate) fn new(model: &Model, p: &Particles, dt: f64) -> Self {
        let interval = (CHECK_EVERY / dt).round().clamp(1.0, 1e15) as u64;
        let start = energy(model, p);
        let gravity_potential: f64 =
            p.x.iter()
                .zip(&p.mass)
                .map(|(x, m)| -m * model.gravity.dot(x))
                .sum();
        let (lo, hi) = summary::bounds(&p.x);
        let extent = if p.is_empty() { 0.0 } else { (hi - lo).norm() };
        let free_mass: f64 = p
            .mass
            .iter()
            .zip(&p.inv_mass)
            .filter(|(_, inv)| **inv != 0.0)
            .map(|(m, _)| m)
            .sum();
        let weight = free_mass * model.gravity.norm() * (extent + 1.0);
        // Kinetic, spring and penalty energy: the total less gravity's potential.
        let own = (start - gravity_potential).abs();
        let carried = collider_allowance(model, (&lo, &hi), free_mass);
        let scale = (own + weight + carried).max(1e-3);
        Self {
            enabled: true,
            interval,
            start,
            scale,
            carried,
            supplied: 0.0,
            sources: Sources::default(),
            air: AirForces::default(),
        }
    }

    /// Forgets what was built for the particles' old numbering.
    pub(crate) fn renumbered(&mut self) {
        self.air = AirForces::default();
    }

    /// Checks the state after step `step` (at time `time`) when a check is due.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn check(
        &mut self,
        model: &Model,
        p: &Particles,
        initial: &Particles,
        step: u64,
        time: f64,
        integrator: Integrator,
        dt: f64,
    ) -> Result<(), Divergence> {
        if !self.enabled || !step.is_multiple_of(self.interval) {
            return Ok(());
        }
        let span = self.interval as f64 * dt;
        let power = self.power(model, p, time);
        self.sources.add(&power, span);
        self.supplied += span * power.total();
        let e = energy(model, p);
        let allowed = if integrator.dissipates() {
            DISSIPATIVE_SLACK * (self.scale - self.carried) + self.carried + 2.0 * self.supplied
        } else {
            GROWTH * self.scale + 2.0 * self.supplied
        };
        // Energy that fell or stayed is no energy from nowhere: never a runaway. A non-finite
        // state is the sanity check's to name; an allowance that is not a number (it never
        // should be) stops nothing.
        if e <= self.start || e - self.start <= allowed || !e.is_finite() || allowed.is_nan() {
            return Ok(());
        }
        let particle = fastest(p);
        let cause = format!("{}{}", self.sources.largest(model), likely_cause(model, p));
        let stable_dt = StabilityEstimate::of(model, initial).max_dt(integrator);
        Err(Divergence {
            step,
            time,
            particle,
            what: format!(
                "moves at {:.3e} m/s: the energy grew from {:.4e} J to {:.4e} J, far beyond \
                 the {:.3e} J that the field, the air, the attachments, the moving pins and the \
                 moving colliders supplied{cause}",
                p.v[particle].norm(),
                self.start,
                e,
                self.supplied
            ),
            integrator,
            dt,
            stable_dt,
            step_stable_dt: stable_dt,
            suggested_dt: super::divergence::suggested(stable_dt, dt),
            solve: None,
        })
    }

    /// The power that forces from outside the springs and gravity put in now, by source,
    /// counting only where they push a particle along its motion.
    fn power(&mut self, model: &Model, p: &Particles, time: f64) -> Power {
        let mut power = Power {
            pins: pin_power(model, p),
            colliders: collider_power(model, p),
            ..Power::default()
        };
        if model.field.is_none() && model.air.is_none() && model.attachments.is_empty() {
            return power;
        }
        self.air.ensure(&model.aero, p.len());
        let air = self
            .air
            .evaluate(model.air.as_ref(), &model.aero, &p.x, &p.v, time);
        for i in 0..p.len() {
            if p.inv_mass[i] == 0.0 {
                continue;
            }
            let (x, v) = (&p.x[i], &p.v[i]);
            power.attachments += model.attachment_force(i, x, v).dot(v).max(0.0);
            if let Some(field) = &model.field {
                power.field += field.sample(x).dot(v).max(0.0);
            }
            if let Some(a) = air.get(i) {
                power.air += a.dot(v).max(0.0);
            }
        }
        power
    }
}

/// The power each source outside the springs and gravity puts in at a check, watts.
#[derive(Clone, Debug, Default)]
struct Power {
    field: f64,
    air: f64,
    attachments: f64,
    pins: f64,
    /// Per collider (zero for the still ones).
    colliders: Vec<f64>,
}

impl Power {
    fn total(&self) -> f64 {
        self.field + self.air + self.attachments + self.pins + self.colliders.iter().sum::<f64>()
    }
}

/// The work each source supplied so far, joules.
#[derive(Clone, Debug, Default)]
struct Sources {
    field: f64,
    air: f64,
    attachments: f64,
    pins: f64,
    colliders: Vec<f64>,
}

impl Sources {
    fn add(&mut self, power: &Power, span: f64) {
        self.field += span * power.field;
        self.air += span * power.air;
        self.attachments += span * power.attachments;
        self.pins += span * power.pins;
        self.colliders
            .resize(power.colliders.len().max(self.colliders.len()), 0.0);
        for (w, p) in self.colliders.iter_mut().zip(&power.colliders) {
            *w += span * p;
        }
    }

    /// The source that supplied the most, said after a `; ` (nothing when none did).
    fn largest(&self, model: &Model) -> String {
        let mut named = vec![
            (self.field, "the force field".to_string()),
            (self.air, "the air".to_string()),
            (self.attachments, "the attachments".to_string()),
            (self.pins, "the moving pins ([body.pin_motion])".to_string()),
        ];
        for (k, &w) in self.colliders.iter().enumerate() {
            if let Some(slot) = model.colliders.get(k) {
                named.push((w, format!("collider[{k}] ({}), moving", slot.shape.name())));
            }
        }
        named
            .into_iter()
            .filter(|(w, _)| *w > 0.0)
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map_or_else(String::new, |(w, name)| {
                format!("; the largest source of work is {name}, {w:.3e} J")
            })
    }
}

/// The most the moving colliders can give the bodies (their work is not summed as the
/// pins' is): for each, every free particle thrown at twice the collider's largest speed
/// (a bounce off it) and lifted by the length of its path, both measured with
/// [`crate::Collider::sweep`] over the bodies' box at the start, on the collider's
/// [`crate::Collider::motion_spans`].
fn collider_allowance(model: &Model, (lo, hi): (&Vec3, &Vec3), free_mass: f64) -> f64 {
    let mut total = 0.0;
    for slot in &model.colliders {
        let (mut speed, mut path) = (0.0_f64, 0.0_f64);
        for (t0, t1) in slot.shape.motion_spans() {
            let s = slot.shape.sweep((t0, t1), lo, hi);
            path += s;
            if t1 > t0 {
                speed = speed.max(s / (t1 - t0));
            }
        }
        total += free_mass * (2.0 * speed * speed + model.gravity.norm() * path);
    }
    total
}

/// The power keyframed pins put in now: each moving pinned particle is held against its
/// springs and its weight, so the holder's force is minus their sum, counted where it
/// pushes along the particle's motion.
fn pin_power(model: &Model, p: &Particles) -> f64 {
    if model.pin_motions.is_empty() {
        return 0.0;
    }
    let mut moving = vec![false; p.len()];
    for m in &model.pin_motions {
        for &i in &m.particles {
            moving[i as usize] = true;
        }
    }
    let held = holding(model, p, &moving);
    (0..p.len())
        .filter(|&i| moving[i])
        .map(|i| held[i].dot(&p.v[i]).max(0.0))
        .sum()
}

/// Per particle flagged in `wanted`, the force that holds it where it is against its
/// springs and its weight: minus their sum (zero for the others).
fn holding(model: &Model, p: &Particles, wanted: &[bool]) -> Vec<Vec3> {
    let mut held = vec![Vec3::zeros(); p.len()];
    for s in &model.springs {
        let (i, j) = (s.i as usize, s.j as usize);
        if !(wanted[i] || wanted[j]) {
            continue;
        }
        let f = s.force(&p.x[i], &p.x[j], &p.v[i], &p.v[j]);
        held[i] -= f;
        held[j] += f;
    }
    for (i, h) in held.iter_mut().enumerate().filter(|(i, _)| wanted[*i]) {
        *h -= model.gravity * p.mass[i];
    }
    held
}

/// The power each moving collider puts in now: a particle touching it (inside it, or
/// within its contact thickness or a point's) is held against its springs and its weight,
/// as a keyed pin is, so the collider's force on it is minus their sum, counted where the
/// collider's surface there moves along it. Still colliders do no work (none is listed
/// when no collider moves, so a check allocates nothing then).
fn collider_power(model: &Model, p: &Particles) -> Vec<f64> {
    if !model.colliders.iter().any(|c| c.shape.is_moving()) {
        return Vec::new();
    }
    let mut power = vec![0.0; model.colliders.len()];
    let free: Vec<bool> = p.inv_mass.iter().map(|&inv| inv != 0.0).collect();
    let held = holding(model, p, &free);
    let point = model.point_thickness();
    for (k, slot) in model.colliders.iter().enumerate() {
        if !slot.shape.is_moving() {
            continue;
        }
        for i in (0..p.len()).filter(|&i| free[i]) {
            let margin = model.margin(i).max(point);
            let mut normal = None;
            slot.shape
                .contacts_within(&p.x[i], 2.0 * margin, &mut |c| normal = Some(c));
            let Some(c) = normal else {
                continue;
            };
            // The collider pushes along its normal only: what holds the particle there.
            let push = held[i].dot(&c.normal).max(0.0);
            let along = slot.shape.velocity(&c.point).dot(&c.normal);
            power[k] += (push * along).max(0.0);
        }
    }
    power
}

/// The fastest particle.
fn fastest(p: &Particles) -> usize {
    (0..p.len())
        .max_by(|&a, &b| p.v[a].norm_squared().total_cmp(&p.v[b].norm_squared()))
        .unwrap_or(0)
}

/// What most likely put the energy in, said after a `; `.
fn likely_cause(model: &Model, p: &Particles) -> String {
    let pins = pin_speed(model);
    let keyed = if pins > 0.0 {
        format!(
            "; the moving pins ([body.pin_motion]) move at up to {} m/s, and pins moved faster \
             than their springs can follow, or whose first key or sample is not where they \
             start, pull their body apart",
            crate::Approx(pins)
        )
    } else {
        String::new()
    };
    format!("{}{keyed}", collider_or_step_cause(model, p))
}

/// The fastest any moving pin moves, m/s ([`PinMotion::speed`]).
fn pin_speed(model: &Model) -> f64 {
    model
        .pin_motions
        .iter()
        .map(PinMotion::speed)
        .fold(0.0, f64::max)
}

/// A collider holding particles, or the usual suspects, said after a `; `.
fn collider_or_step_cause(model: &Model, p: &Particles) -> String {
    for (k, slot) in model.colliders.iter().enumerate() {
        let inside =
            p.x.iter()
                .zip(&p.inv_mass)
                .filter(|(x, inv)| **inv != 0.0 && slot.shape.inside(x))
                .count();
        if inside > 0 {
            return format!(
                "; {inside} particles are inside collider[{k}] ({}): a body that starts in or \
                 is driven through a collider is fought over by its springs and the contact, \
                 which pumps energy in; start the body outside it, with a gap of at least its \
                 thickness",
                slot.shape.name()
            );
        }
    }
    "; likely causes: a body started inside a collider or another body, a contact thickness \
     larger than the gap it starts with, or a step too large for the scheme (see hooke check)"
        .to_string()
}
