//! Divergence: finding the first particle in a bad state, and a message that says what to do.
//!
//! A state is sane when every velocity is finite and every position is within
//! [`SANE_BOUND`] of the origin (docs/physics.md §7). When it is not, the run stops with a
//! [`Divergence`] naming the step, the particle and a step size expected to be stable, from
//! the stability estimate at the *start* of the step: the diverged state itself has no
//! meaningful geometry.

use crate::contact::crowding::Crowded;
use crate::integrator::Integrator;
use crate::model::Model;
use crate::parallel;
use crate::particles::{Particles, SANE_BOUND, Vec3};
use crate::simulation::stability::StabilityEstimate;

/// A run stopped because the state stopped making sense (docs/physics.md §7).
///
/// Its message names the step, the time, the particle and a step size expected to be
/// stable, and says whether the step in use exceeds the stability estimate or not (when it
/// does not, the step size alone does not explain the divergence).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}", self.message())]
pub struct Divergence {
    /// The step that produced the bad state (1-based: the first step is step 1).
    pub step: u64,
    /// Simulated time at the end of that step, in seconds.
    pub time: f64,
    /// The first particle found in a bad state.
    pub particle: usize,
    /// What was wrong with it.
    pub what: String,
    /// The integrator in use.
    pub integrator: Integrator,
    /// The step size in use.
    pub dt: f64,
    /// The integrator's estimated stable step at the run's start, seconds (infinite for
    /// the implicit integrator and for systems without springs): what `hooke check` says.
    pub stable_dt: f64,
    /// The same estimate at the state the diverging step started from, seconds.
    pub step_stable_dt: f64,
    /// A step size expected to be stable: half the estimate, or half the step in use when
    /// that is smaller (the estimate did not explain the divergence, so take margin).
    pub suggested_dt: f64,
    /// When the diverging step was a large step (`vbd`, `newton`): how far its steps are
    /// solved. A step not solved to the end is not backward Euler's, and can gain energy.
    pub solve: Option<Box<SolveState>>,
}

/// How far a large step's solve went, for a divergence's advice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveState {
    /// The iteration budget of a step.
    pub budget: usize,
    /// Whether the diverging step ended at its budget before its stopping rule.
    pub capped: bool,
    /// The stopping tolerance, m/s.
    pub tolerance: f64,
    /// The steps so far that ended at their budget (the diverging one included).
    pub unsolved: u64,
}

/// Where a step left the state, for [`check`].
pub(crate) struct StepEnd<'a> {
    /// The model stepped.
    pub model: &'a Model,
    /// The particles as the step left them.
    pub particles: &'a Particles,
    /// The particles as the run started.
    pub initial: &'a Particles,
    /// The step's start positions, if the integrator saved them; otherwise they are
    /// recovered by undoing `x' = x + dt v'` (symplectic Euler), up to rounding.
    pub start: Option<&'a [Vec3]>,
    /// The integrator's own verdict on the state, if it checked it in its last pass.
    pub verdict: Option<bool>,
    /// The contact phase found the surfaces crushed through themselves (more candidate
    /// pairs than they can hold apart): a divergence whatever the sanity check says.
    pub crowded: Option<Crowded>,
    /// The step's number (1-based), the integrator and its step size.
    pub step: u64,
    pub integrator: Integrator,
    pub dt: f64,
}

/// The divergence check after a step: `Ok` when the state is sane, otherwise the
/// [`Divergence`] with the first bad particle and the estimate at the step's start.
pub(crate) fn check(end: StepEnd<'_>) -> Result<(), Divergence> {
    let p = end.particles;
    if end.crowded.is_none()
        && end
            .verdict
            .unwrap_or_else(|| parallel::all_sane(&p.x, &p.v, SANE_BOUND))
    {
        return Ok(());
    }
    let mut at_start = p.clone();
    match end.start {
        Some(x0) => at_start.x.copy_from_slice(x0),
        None => {
            for (x, v) in at_start.x.iter_mut().zip(&p.v) {
                *x -= v * end.dt;
            }
        }
    }
    let bad = match end.crowded {
        Some(crowded) => Some((farthest(&at_start.x, &p.x), crowding(crowded))),
        None => first_bad(p),
    };
    let Some((particle, what)) = bad else {
        return Ok(());
    };
    // A state that already overflowed has no geometry to linearise at: bound the frequency
    // from the springs' stiffness and the masses alone.
    let finite = at_start.x.iter().all(|x| x.iter().all(|c| c.is_finite()));
    let estimate = if finite {
        StabilityEstimate::of(end.model, &at_start)
    } else {
        StabilityEstimate::bound(end.model, &at_start)
    };
    let step_stable_dt = estimate.max_dt(end.integrator);
    let stable_dt = StabilityEstimate::of(end.model, end.initial).max_dt(end.integrator);
    Err(Divergence {
        step: end.step,
        time: end.step as f64 * end.dt,
        particle,
        what,
        integrator: end.integrator,
        dt: end.dt,
        stable_dt,
        step_stable_dt,
        suggested_dt: suggested(stable_dt, end.dt),
        solve: None,
    })
}

/// The step to advise after a divergence of a run at `dt` whose start's stable estimate is
/// `stable_dt`: half the smaller, never below the shortest step a scene may take
/// ([`crate::integrator::DT_RANGE`]; zero when even that is too long). The estimate of the
/// state a diverging step started from is no guide: that state has often run away already.
pub(crate) fn suggested(stable_dt: f64, dt: f64) -> f64 {
    let half = 0.5 * stable_dt.min(dt);
    if half >= *crate::integrator::DT_RANGE.start() {
        half
    } else {
        0.0
    }
}

/// The particle that moved farthest from `start` to `x` (the lowest-numbered of equals).
fn farthest(start: &[Vec3], x: &[Vec3]) -> usize {
    let mut best = (0, -1.0);
    for (i, (a, b)) in start.iter().zip(x).enumerate() {
        let d = (b - a).norm();
        if d > best.1 {
            best = (i, d);
        }
    }
    best.0
}

/// What a step that crushed the surfaces did to its farthest-moved particle.
fn crowding(crowded: Crowded) -> String {
    format!(
        "moved farthest in a step that left over {} pairs of surface primitives within the \
         contacts' reach of each other, more than surfaces kept a thickness apart can hold: \
         the step crushed or tore them through themselves",
        crowded.limit
    )
}

/// The lowest-numbered particle in a bad state, and what is wrong with it.
fn first_bad(p: &Particles) -> Option<(usize, String)> {
    parallel::find_first(p.len(), |i| {
        let (x, v) = (&p.x[i], &p.v[i]);
        if !(x.iter().all(|c| c.is_finite()) && v.iter().all(|c| c.is_finite())) {
            Some((i, "is not finite".to_string()))
        } else if x.amax() > SANE_BOUND {
            Some((i, format!("is {:.3e} m from the origin", x.norm())))
        } else {
            None
        }
    })
}

impl Divergence {
    /// The advice to take a step of [`Divergence::suggested_dt`], or, when no step Hooke
    /// accepts would do, to look at the scene instead.
    fn smaller(&self) -> String {
        if self.suggested_dt > 0.0 {
            format!("dt = {:.3e} s", self.suggested_dt)
        } else {
            format!(
                "no step Hooke accepts (down to {:e} s) would be stable: the scene's stiffness \
                 against its masses is out of reach (see hooke check)",
                crate::integrator::DT_RANGE.start()
            )
        }
    }

    fn message(&self) -> String {
        use crate::Approx;
        let head = format!(
            "diverged at step {} (t = {} s): particle {} {}",
            self.step,
            crate::Approx(self.time),
            self.particle,
            self.what
        );
        // The estimate at the run's start is `hooke check`'s; the diverging step's may be
        // smaller where the state has since stretched or sped up.
        let here = if self.step_stable_dt < 0.95 * self.stable_dt {
            format!(
                " ({:.3e} s at the state the step started from)",
                self.step_stable_dt
            )
        } else {
            String::new()
        };
        let advice = if self.dt <= self.stable_dt && self.dt > self.step_stable_dt {
            format!(
                "the {} step dt = {} s is within its stable estimate of {:.3e} s at the run's \
                 start (as hooke check says), but not the {:.3e} s of the state the step started \
                 from, which had already run away: look for forces that stiffen as the state \
                 moves (a strong wind, a stiff penalty collider); {} may help",
                self.integrator,
                Approx(self.dt),
                self.stable_dt,
                self.step_stable_dt,
                self.smaller()
            )
        } else if self.dt > self.stable_dt {
            format!(
                "the {} step dt = {} s exceeds its stable estimate of {:.3e} s at the run's start \
                 (as hooke check says){here}; use {} or smaller",
                self.integrator,
                Approx(self.dt),
                self.stable_dt,
                self.smaller()
            )
        } else if let Some(solve) = &self.solve {
            let ended = if solve.capped {
                format!(
                    "ended at its budget of {} iterations before its tolerance of {} m/s",
                    solve.budget,
                    Approx(solve.tolerance)
                )
            } else {
                format!(
                    "met its stopping rule, which leaves up to {} m/s of a particle's motion \
                     unsolved",
                    Approx(solve.tolerance)
                )
            };
            format!(
                "the {} step {ended} ({} of the {} steps so far ended at their budget; \
                 docs/physics.md §4.1, \"Stopping rule and accuracy\"): a step not solved to \
                 the end is not backward Euler's, and can gain energy; solve the steps further \
                 with a tighter --tolerance and more --iterations{}",
                self.integrator,
                solve.unsolved,
                self.step,
                if self.integrator == Integrator::Vbd {
                    ", or take `--integrator newton`, whose line search takes no move that \
                     raises the step's energy"
                } else {
                    ""
                }
            )
        } else {
            let estimate = if self.stable_dt.is_finite() {
                format!("its stable estimate of {:.3e} s", self.stable_dt)
            } else {
                "its stable estimate (any dt)".to_string()
            };
            format!(
                "the {} step dt = {} s is within {estimate}, so the step size alone does not \
                 explain this: look for a very stiff or degenerate spring, a stiff penalty \
                 collider, a strong force field or an extreme initial state; a smaller step, \
                 {}, may still help",
                self.integrator,
                Approx(self.dt),
                self.smaller()
            )
        };
        format!("{head}; {advice}")
    }
}
