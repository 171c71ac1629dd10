//! Time integrators (docs/physics.md §4), all sharing one force evaluator and one reusable workspace.
//!
//! Every scheme advances the state `s = (x, v)` with `a(s) = F(s) / m`. Velocity-level
//! collision responses are not the integrator's business: [`crate::Simulation`] applies them
//! once after the full step.

mod blocks;
mod euler;
mod implicit;
mod midpoint;
mod newton;
mod rk4;
mod symplectic;
mod vbd;

use crate::assembly::kernel::Kernel;
use crate::assembly::{Assembly, BLOCK};
use crate::forces::air::AirForces;
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, Vec3};
use std::fmt;
use std::str::FromStr;

pub(crate) use blocks::Sym3;
pub(crate) use vbd::swept::collider_gap;

/// The range of step sizes a scene may take, seconds. Every integrator divides by `dt²`
/// (block descent's inertia `m/dt²`, implicit Euler's `M/dt`, the stable-step estimates),
/// and the contact and stability figures multiply by it: outside this range those numbers
/// leave what doubles hold with room to spare, and no scene means such a step (a
/// femtosecond, or a step of over a quarter of an hour).
pub const DT_RANGE: std::ops::RangeInclusive<f64> = 1e-15..=1e3;

/// How an iterative large-step integrator (block descent) ends a step: when its last
/// iteration moved no free particle faster than `tolerance` (its move over the step, m/s:
/// IPC's rule, in the units users think in), or after `iterations`. A residual is kept as
/// evidence, never as the rule (docs/physics.md §4.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StopRule {
    /// The velocity below which the last update counts as converged, m/s.
    pub tolerance: f64,
    /// The iteration budget of a step.
    pub iterations: usize,
}

impl StopRule {
    /// Block descent's defaults (chosen by measurement: benches/README.md).
    pub const VBD: StopRule = StopRule {
        tolerance: 1e-2,
        iterations: 24,
    };

    /// Newton's defaults (chosen by measurement: benches/README.md).
    pub const NEWTON: StopRule = StopRule {
        tolerance: 1e-2,
        iterations: 100,
    };
}

/// Where a large-step integrator's time went, summed over its steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveTimes {
    /// Contact detection, the first guess and recolouring.
    pub detection: std::time::Duration,
    /// The colour sweeps (the local solves).
    pub sweeps: std::time::Duration,
    /// The coarse correction.
    pub coarse: std::time::Duration,
    /// The acceleration (and the copies that keep its iterates).
    pub acceleration: std::time::Duration,
    /// Builds of the self-contact pair list.
    pub pair_list_builds: u64,
    /// Their time (part of `detection`).
    pub pair_list_building: std::time::Duration,
}

/// A stopwatch read in laps: each [`Lap::lap`] is the time since the last.
pub(crate) struct Lap(std::time::Instant);

impl Lap {
    pub(crate) fn start() -> Self {
        Self(std::time::Instant::now())
    }

    /// The time since the last lap (or the start), and a new lap begins.
    pub(crate) fn lap(&mut self) -> std::time::Duration {
        let now = std::time::Instant::now();
        let d = now - self.0;
        self.0 = now;
        d
    }
}

/// The integration scheme; maps 1:1 to the `--integrator` flag and the scene files' names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Integrator {
    /// Explicit (forward) Euler: position and velocity both from the old state. Order 1; only
    /// stable with enough damping.
    Euler,
    /// Semi-implicit (symplectic) Euler: new velocity first, then position with it. Order 1;
    /// stable for `dt < 2 / ω_max`, energy bounded.
    Symplectic,
    /// Explicit midpoint (RK2). Order 2.
    Midpoint,
    /// Classic fourth-order Runge–Kutta. Order 4; stable for `dt < 2.8 / ω_max`.
    Rk4,
    /// Implicit (backward) Euler linearised at the current state and solved with
    /// conjugate gradients (Baraff & Witkin 1998). Order 1; stable for any `dt`, damps.
    Implicit,
    /// Implicit Euler solved by vertex block descent, every update bounded so that no
    /// surface crosses a collider or another surface (docs/physics.md §4.1). Order 1; stable
    /// for any `dt`, damps; contacts at the bodies' thickness, with friction.
    Vbd,
    /// Implicit Euler solved by Newton's method: each iteration a global solve (conjugate
    /// gradients) and a line search on the step's energy, within block descent's bounds
    /// (docs/physics.md §4.2). Order 1; stable for any `dt`, damps; converges where block
    /// descent cannot, on stiff and volumetric bodies.
    Newton,
}

impl Integrator {
    /// All integrators, in the order of docs/physics.md §4.
    pub const ALL: [Integrator; 7] = [
        Self::Euler,
        Self::Symplectic,
        Self::Midpoint,
        Self::Rk4,
        Self::Implicit,
        Self::Vbd,
        Self::Newton,
    ];

    /// The name used on the command line and in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Euler => "euler",
            Self::Symplectic => "symplectic",
            Self::Midpoint => "midpoint",
            Self::Rk4 => "rk4",
            Self::Implicit => "implicit",
            Self::Vbd => "vbd",
            Self::Newton => "newton",
        }
    }

    /// The most iterations its solver takes in one step (block descent's sweeps, the
    /// implicit step's conjugate gradients); `None` for the explicit schemes.
    pub fn iteration_cap(self) -> Option<usize> {
        match self {
            Self::Vbd => Some(StopRule::VBD.iterations),
            Self::Newton => Some(StopRule::NEWTON.iterations),
            Self::Implicit => Some(implicit::CG_MAX_ITERATIONS),
            _ => None,
        }
    }

    /// Whether a step takes energy out and nothing after it puts any back: implicit Euler
    /// solved with its contacts inside the solve (block descent, Newton), so no contact
    /// phase moves a particle out of a collider after the step. Such a run may not gain more
    /// than a hundredth of its energy scale beyond the work done on it (docs/physics.md §7).
    pub fn dissipates(self) -> bool {
        self.solves_contacts()
    }

    /// Whether its contacts are inside its solve, bounded at the bodies' thickness (block
    /// descent and Newton): no contact phase runs after its steps, and a moving collider or
    /// keyed pins split a step into parts (docs/physics.md §4.1).
    pub fn solves_contacts(self) -> bool {
        matches!(self, Self::Vbd | Self::Newton)
    }

    /// Order of convergence on smooth problems.
    pub fn order(self) -> u32 {
        match self {
            Self::Euler | Self::Symplectic => 1,
            Self::Midpoint => 2,
            Self::Rk4 => 4,
            Self::Implicit | Self::Vbd | Self::Newton => 1,
        }
    }

    /// Force evaluations per step.
    pub fn stages(self) -> usize {
        match self {
            Self::Euler | Self::Symplectic => 1,
            Self::Midpoint => 2,
            Self::Rk4 => 4,
            // One evaluation, then a linear solve of a few to a few hundred iterations.
            Self::Implicit => 1,
            // A detection, then local (or global) solves: counted as one evaluation.
            Self::Vbd | Self::Newton => 1,
        }
    }

    /// The radius of the scheme's stability region along the imaginary axis: an undamped
    /// oscillation of angular frequency `ω` stays bounded for `ω dt` below it. Infinite for
    /// the implicit scheme, which is stable for every step. Each scheme's module states its
    /// own (see [`crate::StabilityEstimate::max_dt`]).
    pub fn stability_radius(self) -> f64 {
        match self {
            Self::Euler => euler::STABILITY_RADIUS,
            Self::Symplectic => symplectic::STABILITY_RADIUS,
            Self::Midpoint => midpoint::STABILITY_RADIUS,
            Self::Rk4 => rk4::STABILITY_RADIUS,
            Self::Implicit => implicit::STABILITY_RADIUS,
            Self::Vbd => vbd::STABILITY_RADIUS,
            Self::Newton => newton::STABILITY_RADIUS,
        }
    }

    /// Advances `particles` from time `t` by `dt` seconds under `model`, without collision
    /// responses (`t` matters to forces that vary in time, such as a gusting wind).
    /// `held` marks particles a stick response holds (the implicit scheme keeps them out of
    /// its solve; the explicit ones leave that to the responses); a particle past its end
    /// is not held, so `&[]` holds none. Returns what the step
    /// did that its caller's checks need to know.
    pub(crate) fn step(
        self,
        model: &Model,
        particles: &mut Particles,
        ws: &mut Workspace,
        (t, dt): (f64, f64),
        held: &[bool],
    ) -> StepReport {
        ws.ensure(model, particles.len(), self);
        match self {
            Self::Euler => euler::step(model, particles, (t, dt), ws),
            Self::Symplectic => symplectic::step(model, particles, (t, dt), ws),
            Self::Midpoint => midpoint::step(model, particles, (t, dt), ws),
            Self::Rk4 => rk4::step(model, particles, (t, dt), ws),
            Self::Implicit => implicit::step(model, particles, (t, dt), ws, held),
            Self::Vbd => vbd::step(model, particles, (t, dt), ws),
            Self::Newton => newton::step(model, particles, (t, dt), ws),
        }
    }
}

/// What an integrator's step reports back: whether it saved the step's start positions and,
/// for schemes that check the state in their last pass, their verdict on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct StepReport {
    /// Whether [`Workspace::start_positions`] holds the positions at the step's start.
    /// Symplectic Euler saves them only for models with a contact phase: the copy costs a
    /// fifth of a large cloth's step.
    pub saved_start: bool,
    /// `Some(true)` when the scheme found every position within [`crate::SANE_BOUND`] and
    /// every velocity finite, `Some(false)` when it did not, `None` when it did not look
    /// (the caller then scans the state itself).
    pub verdict: Option<bool>,
}

impl StepReport {
    /// The report of a scheme that saved its start and left the state unchecked.
    const SAVED: Self = Self {
        saved_start: true,
        verdict: None,
    };
}

impl fmt::Display for Integrator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The error for an integrator name that is not one of [`Integrator::ALL`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown integrator '{0}': expected one of euler, symplectic, midpoint, rk4, implicit, vbd"
)]
pub struct UnknownIntegrator(pub String);

impl FromStr for Integrator {
    type Err = UnknownIntegrator;

    /// Parses a name case-insensitively (`RK4` and `Euler` as in jello worlds).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|i| i.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| UnknownIntegrator(s.to_string()))
    }
}

/// Stage buffers reused from step to step, so that stepping allocates nothing.
#[derive(Clone, Debug, Default)]
pub struct Workspace {
    pub(crate) assembly: Assembly,
    /// Positions at the start of the last step, when its [`StepReport::saved_start`].
    pub(crate) x0: Vec<Vec3>,
    /// Stage derivatives: `kx` are velocities, `kv` accelerations (empty for symplectic
    /// Euler, as are `xt` and `vt`).
    pub(crate) kx: [Vec<Vec3>; 4],
    pub(crate) kv: [Vec<Vec3>; 4],
    /// A trial state for evaluating stages.
    pub(crate) xt: Vec<Vec3>,
    pub(crate) vt: Vec<Vec3>,
    /// The implicit integrator's blocks and preconditioner.
    pub(crate) implicit: implicit::ImplicitBuffers,
    /// The block-descent integrator's colouring, detection and buffers (Newton's step
    /// shares its detection, targets and counts).
    pub(crate) vbd: vbd::VbdBuffers,
    /// Newton's system and conjugate-gradient vectors.
    pub(crate) newton: newton::NewtonBuffers,
    /// The air forces' incidences and buffers.
    pub(crate) air: AirForces,
    /// The force loop's compilation, when not the detected one.
    pub(crate) kernel: Option<Kernel>,
    /// How block descent ends a step, when not its default.
    pub(crate) stop: Option<StopRule>,
    /// Asked between the large steps' iterations (and inside Newton's conjugate gradients):
    /// when it answers `true`, the step ends where its iterate is, every update still
    /// within its bounds, so that an interrupt is seen within a fraction of a second at any
    /// tolerance.
    pub(crate) cancel: Option<fn() -> bool>,
}

/// Whether the large step under way should end now ([`Workspace::cancel`]).
#[inline]
pub(crate) fn cancelled(cancel: Option<fn() -> bool>) -> bool {
    cancel.is_some_and(|f| f())
}

impl Workspace {
    /// Conjugate-gradient iterations of the last implicit step, or of the last Newton step
    /// (all its iterations summed; 0 for other integrators).
    pub fn cg_iterations(&self) -> usize {
        self.implicit.iterations + self.newton.cg_iterations
    }

    /// Iterations of the last block-descent step (0 for other integrators).
    pub fn vbd_iterations(&self) -> usize {
        self.vbd.iterations
    }

    /// Contact detections of the last block-descent step (0 for other integrators).
    pub fn vbd_detections(&self) -> usize {
        self.vbd.detections
    }

    /// Whether the last step ended at an iteration cap without meeting its solver's
    /// stopping rule: block descent's iterations, or the implicit step's conjugate gradients
    /// (`false` for the explicit integrators).
    pub fn capped(&self) -> bool {
        self.vbd.capped || self.implicit.iterations >= implicit::CG_MAX_ITERATIONS
    }

    /// The last block-descent step's residual: the largest force left on a free particle
    /// over its weight (docs/physics.md §4.1; 0 for other integrators, and unless asked
    /// for with [`crate::Simulation::measure_residuals`]).
    pub fn vbd_residual(&self) -> f64 {
        self.vbd.residual
    }

    /// The largest move of the last block-descent step's last iteration over the step,
    /// m/s: what its [`StopRule`] compares with its tolerance.
    pub fn vbd_last_speed(&self) -> f64 {
        self.vbd.last_speed
    }

    /// Parts the last block-descent step was taken in (one unless a collider or pins move).
    pub fn vbd_parts(&self) -> u32 {
        self.vbd.step_parts
    }

    /// Where block descent's time went, summed over the steps so far.
    pub fn solve_times(&self) -> SolveTimes {
        let (pair_list_builds, pair_list_building) = self.vbd.detection.builds();
        SolveTimes {
            pair_list_builds,
            pair_list_building,
            ..self.vbd.times
        }
    }

    /// The rule block descent (or Newton, `newton`) ends its steps by.
    pub fn stop_rule_of(&self, integrator: Integrator) -> StopRule {
        self.stop.unwrap_or(if integrator == Integrator::Newton {
            StopRule::NEWTON
        } else {
            StopRule::VBD
        })
    }

    /// The rule block descent ends its steps by.
    pub fn stop_rule(&self) -> StopRule {
        self.stop_rule_of(Integrator::Vbd)
    }

    /// Lays out `model`'s springs and sizes the buffers `integrator` uses for `particles`
    /// particles, unless they already fit: on the first step, or at once from
    /// [`crate::Simulation::new`].
    pub(crate) fn ensure(&mut self, model: &Model, particles: usize, integrator: Integrator) {
        let springs = model.springs.len();
        // Block descent and Newton sum springs per particle (their graph), never through
        // the explicit force loop: its layout would be 2.3 MB of a 128² cloth's memory.
        let summed = !matches!(integrator, Integrator::Vbd | Integrator::Newton);
        if summed && !self.assembly.fits(particles, springs) {
            self.assembly = Assembly::new(particles, &model.springs);
        }
        if let Some(kernel) = self.kernel {
            self.assembly.set_kernel(kernel);
        }
        self.air.ensure(&model.aero, particles);
        let zero = Vec3::zeros();
        self.x0.resize(particles, zero);
        // Symplectic Euler updates the state in place, and block descent and Newton keep
        // their own buffers: none has stages. At a million particles the ten stage buffers
        // would be 240 MB to allocate and zero.
        let stages = match integrator {
            Integrator::Symplectic | Integrator::Vbd | Integrator::Newton => 0,
            _ => particles,
        };
        for buf in [&mut self.xt, &mut self.vt]
            .into_iter()
            .chain(self.kx.iter_mut())
            .chain(self.kv.iter_mut())
        {
            buf.resize(stages, zero);
        }
    }

    /// The compilation of the force loop in use.
    pub fn kernel(&self) -> Kernel {
        self.kernel.unwrap_or_else(Kernel::detect)
    }

    /// Positions at the start of the last step, if `report` (that step's) says they were
    /// saved.
    pub(crate) fn start_positions(&self, report: StepReport) -> Option<&[Vec3]> {
        report.saved_start.then_some(self.x0.as_slice())
    }
}

/// Per-particle updates in parallel blocks of [`BLOCK`] particles.
fn for_blocks(
    a: &mut [Vec3],
    b: &mut [Vec3],
    f: impl Fn(usize, &mut [Vec3], &mut [Vec3]) + Sync + Send,
) {
    parallel::for_blocks(BLOCK, a, b, f);
}
