//! A running system: particles, model, integrator and step size, stepped with divergence checks.

use crate::integrator::{Integrator, Workspace};
use crate::kernel::Kernel;
use crate::model::{Attachment, Model};
use crate::parallel;
use crate::particles::{Particles, Vec3};
use crate::stability::StabilityEstimate;

/// Positions beyond this many metres from the origin count as divergence: no scene in Hooke
/// is larger than a few metres, and an explicit blow-up passes this bound within a few steps.
pub const SANE_BOUND: f64 = 1.0e6;

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
    /// The integrator's estimated stable step at the step's start, seconds (infinite for
    /// the implicit integrator and for systems without springs).
    pub stable_dt: f64,
    /// A step size expected to be stable: half the estimate, or half the step in use when
    /// that is smaller (the estimate did not explain the divergence, so take margin).
    pub suggested_dt: f64,
}

impl Divergence {
    fn message(&self) -> String {
        use crate::Num;
        let head = format!(
            "diverged at step {} (t = {} s): particle {} {}",
            self.step,
            Num(self.time),
            self.particle,
            self.what
        );
        let advice = if self.dt > self.stable_dt {
            format!(
                "the {} step dt = {} s exceeds its stable estimate of {:.3e} s; use dt = {:.3e} s \
                 or smaller",
                self.integrator,
                Num(self.dt),
                self.stable_dt,
                self.suggested_dt
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
                 dt = {:.3e} s, may still help",
                self.integrator,
                Num(self.dt),
                self.suggested_dt
            )
        };
        format!("{head}; {advice}")
    }
}

/// A mass-spring system being simulated.
///
/// ```
/// use hooke_core::{Integrator, Model, Particles, Simulation, Vec3};
/// let mut particles = Particles::default();
/// particles.push(Vec3::new(0.0, 10.0, 0.0), Vec3::zeros(), 1.0);
/// let model = Model { gravity: Vec3::new(0.0, -9.81, 0.0), ..Model::default() };
/// let mut sim = Simulation::new(particles, model, Integrator::Symplectic, 1e-3);
/// sim.advance(1000).unwrap();
/// assert!((sim.time() - 1.0).abs() < 1e-12);
/// assert!(sim.particles().x[0].y < 5.2); // fell about g/2 ≈ 4.9 m
/// ```
#[derive(Debug)]
pub struct Simulation {
    particles: Particles,
    model: Model,
    integrator: Integrator,
    dt: f64,
    step: u64,
    workspace: Workspace,
}

impl Simulation {
    /// A simulation at step 0. Pinned particles have their velocity zeroed.
    ///
    /// The solver's layout of the springs and its buffers are built here, not on the first
    /// step (390k springs take about 20 ms to sort and lay out), so every step costs the
    /// same and a timed run times steps only.
    pub fn new(mut particles: Particles, model: Model, integrator: Integrator, dt: f64) -> Self {
        for i in 0..particles.len() {
            if particles.is_pinned(i) {
                particles.v[i] = Vec3::zeros();
            }
        }
        let mut workspace = Workspace::default();
        workspace.ensure(&model, particles.len());
        Self {
            particles,
            model,
            integrator,
            dt,
            step: 0,
            workspace,
        }
    }

    /// The current particles.
    pub fn particles(&self) -> &Particles {
        &self.particles
    }

    /// The force model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Replaces the model's attachments (particles tied to points in space), e.g. to follow
    /// a mouse grab; takes effect from the next step.
    pub fn set_attachments(&mut self, attachments: Vec<Attachment>) {
        self.model.attachments = attachments;
    }

    /// Runs the force loop compiled for `kernel` (see [`Kernel`]); the widest available is
    /// the default. A kernel the CPU lacks is refused with the best it has.
    pub fn set_kernel(&mut self, kernel: Kernel) -> Result<(), Kernel> {
        if kernel <= Kernel::detect() {
            self.workspace.kernel = Some(kernel);
            Ok(())
        } else {
            Err(Kernel::detect())
        }
    }

    /// The integrators' buffers (for figures such as [`Workspace::cg_iterations`]).
    pub fn workspace(&self) -> &Workspace {
        &self.workspace
    }

    /// The integrator in use.
    pub fn integrator(&self) -> Integrator {
        self.integrator
    }

    /// The step size in seconds.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// Simulated time in seconds, `steps · dt` computed as one product.
    pub fn time(&self) -> f64 {
        self.step as f64 * self.dt
    }

    /// Advances one step: the integrator, then the contact phase (collision responses,
    /// feature and self contacts, see [`crate::contact`]), then the divergence check.
    pub fn step(&mut self) -> Result<(), Divergence> {
        parallel::on_worker(|| self.step_here())
    }

    /// [`Simulation::step`] on the current thread.
    fn step_here(&mut self) -> Result<(), Divergence> {
        self.integrator.step(
            &self.model,
            &mut self.particles,
            self.dt,
            &mut self.workspace,
        );
        let ws = &mut self.workspace;
        let moved = self.model.has_contact_phase()
            && crate::contact::resolve(
                &self.model,
                &mut self.particles,
                &ws.x0,
                &mut ws.stuck,
                &mut ws.contacts,
            );
        self.step += 1;
        // The integrator's own check stands unless contacts moved particles after it.
        let sane = if moved { None } else { ws.sane };
        self.check(sane)
    }

    /// Advances `steps` steps, stopping at the first divergence.
    pub fn advance(&mut self, steps: u64) -> Result<(), Divergence> {
        parallel::on_worker(|| {
            for _ in 0..steps {
                self.step_here()?;
            }
            Ok(())
        })
    }

    /// The highest-frequency estimate of the system at its current state.
    pub fn stability(&self) -> StabilityEstimate {
        StabilityEstimate::of(&self.model, &self.particles)
    }

    /// The divergence check; `sane` is the integrator's verdict on the state, if it gave one.
    fn check(&self, sane: Option<bool>) -> Result<(), Divergence> {
        let p = &self.particles;
        if sane.unwrap_or_else(|| parallel::all_sane(&p.x, &p.v, SANE_BOUND)) {
            return Ok(());
        }
        let bad = parallel::find_first(p.len(), |i| {
            let (x, v) = (&p.x[i], &p.v[i]);
            if !(x.iter().all(|c| c.is_finite()) && v.iter().all(|c| c.is_finite())) {
                Some((i, "is not finite".to_string()))
            } else if x.amax() > SANE_BOUND {
                Some((i, format!("is {:.3e} m from the origin", x.norm())))
            } else {
                None
            }
        });
        match bad {
            None => Ok(()),
            Some((particle, what)) => {
                // Estimate at the step's start: the diverged state has no meaningful geometry.
                let mut at_start = self.particles.clone();
                match self.workspace.start_positions() {
                    Some(x0) => at_start.x.copy_from_slice(x0),
                    // Symplectic Euler moved every particle by `dt v`; undone up to rounding.
                    None => {
                        for (x, v) in at_start.x.iter_mut().zip(&p.v) {
                            *x -= v * self.dt;
                        }
                    }
                }
                // A state that already overflowed has no geometry to linearise at: bound the
                // frequency from the springs' stiffness and the masses alone.
                let finite = at_start.x.iter().all(|x| x.iter().all(|c| c.is_finite()));
                let estimate = if finite {
                    StabilityEstimate::of(&self.model, &at_start)
                } else {
                    StabilityEstimate::bound(&self.model, &at_start)
                };
                let stable_dt = estimate.max_dt(self.integrator);
                Err(Divergence {
                    step: self.step,
                    time: self.time(),
                    particle,
                    what,
                    integrator: self.integrator,
                    dt: self.dt,
                    stable_dt,
                    suggested_dt: 0.5 * stable_dt.min(self.dt),
                })
            }
        }
    }
}
