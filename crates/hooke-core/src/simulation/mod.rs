//! A running system: particles, model, integrator and step size, stepped with divergence checks.
//!
//! A step is the integrator's (which reports back a [`StepReport`]), then the contact phase,
//! then the divergence check of [`crate::simulation::divergence`], which trusts the integrator's verdict
//! unless contacts moved particles after it.

pub(crate) mod divergence;
mod layers;
pub(crate) mod notice;
pub(crate) mod renumber;
pub(crate) mod runaway;
pub(crate) mod stability;
pub(crate) mod start;
pub(crate) mod summary;
pub(crate) mod swept;
pub(crate) mod unsolved;
mod watch;

use crate::assembly::kernel::Kernel;
use crate::contact::{self, ContactState, ContactStats};
use crate::forces::air::Air;
use crate::integrator::{Integrator, StepReport, Workspace};
use crate::model::{Attachment, Model};
use crate::parallel;
use crate::particles::{Particles, Vec3};
use divergence::{Divergence, StepEnd};
use layers::LayerWatch;
use notice::{Cause, Notice, Notices, Through};
use renumber::Renumbering;
use runaway::EnergyWatch;
use stability::StabilityEstimate;
use unsolved::Unsolved;
use watch::CrossingWatch;

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
    /// The contact phase's state, held particles included.
    contacts: ContactState,
    /// The last step's report (before the first step: nothing saved, nothing checked).
    last: StepReport,
    /// Whether every loop of a step runs inline (a system of a few particles): a step then
    /// stays on the calling thread instead of hopping onto a pool worker, which would cost
    /// more than the step.
    inline: bool,
    /// The watch for energy from nowhere ([`runaway`]).
    watch: EnergyWatch,
    /// The state the run started from, for the stable-step estimate a divergence names
    /// (the one `hooke check` gives).
    initial: Particles,
    /// The crossing watch ([`watch`]), the watch on layers after a large step
    /// ([`layers`]), and what they found.
    crossings: CrossingWatch,
    layers: LayerWatch,
    notices: Notices,
    /// The steps ended at the solver's budget.
    unsolved: Unsolved,
}

/// Why [`Simulation::renumber`] refused a renumbering.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RenumberError {
    /// It numbers another count of particles.
    #[error("a renumbering of {found} particles for a simulation of {expected}")]
    Count {
        /// The simulation's particles.
        expected: usize,
        /// The renumbering's.
        found: usize,
    },
    /// It moves a particle out of its body's range.
    #[error("a renumbering that moves particles between bodies")]
    Body,
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
        workspace.ensure(&model, particles.len(), integrator);
        let contacts = ContactState::new(particles.len());
        let inline = particles.len() <= crate::assembly::REDUCE_BLOCK
            // One partition of springs (see `partition_size`).
            && model.springs.len() <= crate::assembly::PARTITION_MIN / 4
            && !model.surfaces.iter().any(crate::model::surface::Surface::is_active);
        let watch = EnergyWatch::new(&model, &particles, dt);
        Self {
            initial: particles.clone(),
            particles,
            model,
            integrator,
            dt,
            step: 0,
            workspace,
            watch,
            contacts,
            last: StepReport {
                saved_start: false,
                verdict: None,
            },
            inline,
            crossings: CrossingWatch::default(),
            layers: LayerWatch::default(),
            notices: Notices::default(),
            unsolved: Unsolved::default(),
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

    /// Replaces the air the system moves in (`None`: vacuum), e.g. to turn the wind off and
    /// on; takes effect from the next step. The surfaces air acts on stay the model's.
    pub fn set_air(&mut self, air: Option<Air>) {
        self.model.air = air;
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

    /// Ends block descent's steps by `rule` instead of its defaults
    /// ([`crate::StopRule::VBD`]).
    pub fn set_stop_rule(&mut self, rule: crate::StopRule) {
        self.workspace.stop = Some(rule);
    }

    /// Installs a question the iterative steps (`vbd`, `newton`, `implicit`) ask between
    /// their iterations: when `cancel` answers `true` the step under way ends early where
    /// it is (`vbd` and `newton` within their bounds, as a capped step; `implicit` with its
    /// linear solve unfinished) and skips its contact phase and watches, so that the
    /// caller, which asked for it (Ctrl-C) and must keep no state after it, can stop the
    /// run within a fraction of a second whatever the tolerance and iteration budget.
    pub fn set_cancel(&mut self, cancel: fn() -> bool) {
        self.workspace.cancel = Some(cancel);
    }

    /// Whether block descent measures each step's residual (a sweep's cost; the benchmark
    /// reports it as evidence).
    pub fn measure_residuals(&mut self, on: bool) {
        self.workspace.vbd.evidence = on;
    }

    /// The integrators' buffers (for figures such as [`Workspace::cg_iterations`]).
    pub fn workspace(&self) -> &Workspace {
        &self.workspace
    }

    /// Makes the contact phase test every candidate pair, and every particle against every
    /// collider, at every step instead of skipping what displacement bounds show cannot
    /// touch. The results are the same bits either way; this exists so that tests can show
    /// it.
    #[doc(hidden)]
    pub fn set_exhaustive_contacts(&mut self, exhaustive: bool) {
        self.contacts.exhaustive = exhaustive;
        self.contacts.face.clear();
    }

    /// Figures of the contact phase: its wall time so far, candidate rebuilds, proximities.
    pub fn contact_stats(&self) -> ContactStats {
        self.contacts.stats
    }

    /// Positions at the start of the last step (every integrator keeps them; `None` before
    /// the first step).
    pub fn start_positions(&self) -> Option<&[Vec3]> {
        self.workspace.start_positions(self.last)
    }

    /// The ranges of particles whose numbering a renumbering must keep to themselves: the
    /// bodies with surfaces, or all particles as one range when there are none.
    pub fn bodies(&self) -> Vec<std::ops::Range<usize>> {
        if self.model.surfaces.is_empty() {
            std::iter::once(0..self.particles.len()).collect()
        } else {
            self.model
                .surfaces
                .iter()
                .map(|s| s.particles.clone())
                .collect()
        }
    }

    /// Renumbers the particles and every index the model holds (see [`Renumbering`]):
    /// the same physics, with particle `i` now `r.new_index(i)`. The solver's layout is
    /// rebuilt and contact state starts afresh, as at step 0.
    pub fn renumber(&mut self, r: &Renumbering) -> Result<(), RenumberError> {
        if r.len() != self.particles.len() {
            return Err(RenumberError::Count {
                expected: self.particles.len(),
                found: r.len(),
            });
        }
        if !r.keeps(self.model.surfaces.iter().map(|s| s.particles.clone())) {
            return Err(RenumberError::Body);
        }
        self.particles = r.particles(&self.particles);
        self.initial = r.particles(&self.initial);
        r.model(&mut self.model);
        let (kernel, stop, cancel) = (
            self.workspace.kernel,
            self.workspace.stop,
            self.workspace.cancel,
        );
        let evidence = self.workspace.vbd.evidence;
        self.workspace = Workspace {
            kernel,
            stop,
            cancel,
            ..Workspace::default()
        };
        self.workspace.vbd.evidence = evidence;
        self.workspace
            .ensure(&self.model, self.particles.len(), self.integrator);
        self.contacts = ContactState::new(self.particles.len());
        // The crossing watch lists the surfaces' particles by number.
        self.crossings = CrossingWatch::default();
        self.watch.renumbered();
        self.last = StepReport {
            saved_start: false,
            verdict: None,
        };
        Ok(())
    }

    /// Renumbers the particles of each body in an order with locality
    /// ([`Renumbering::by_locality`]) and returns the renumbering, to map particle numbers
    /// the caller holds.
    pub fn renumber_for_locality(&mut self) -> Renumbering {
        let r = Renumbering::by_locality(&self.particles.x, &self.model.springs, &self.bodies());
        self.renumber(&r)
            .expect("a body-keeping renumbering of these particles");
        r
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
        if self.inline {
            return self.step_here();
        }
        parallel::on_worker(|| self.step_here())
    }

    /// [`Simulation::step`] on the current thread.
    fn step_here(&mut self) -> Result<(), Divergence> {
        let time = self.time();
        let report = if self.integrator.solves_contacts()
            && (self.model.has_moving_colliders() || !self.model.pin_motions.is_empty())
        {
            self.step_swept(time)
        } else {
            for slot in &mut self.model.colliders {
                slot.shape.advance_to(time, time + self.dt);
            }
            self.start_pins(time, self.dt);
            self.integrator.step(
                &self.model,
                &mut self.particles,
                &mut self.workspace,
                (time, self.dt),
                &self.contacts.held,
            )
        };
        self.last = report;
        if crate::integrator::cancelled(self.workspace.cancel) {
            // The caller asked to stop (`set_cancel`) and keeps nothing of this step: its
            // contact phase and watches (seconds on a large cloth) would only delay it.
            self.step += 1;
            self.end_pins(time + self.dt);
            return Ok(());
        }
        // Every scheme saves its start positions when the model has a contact phase.
        // Block descent keeps its contacts inside its own iterations.
        let phase = if self.model.has_contact_phase() && !self.integrator.solves_contacts() {
            contact::phase(
                &self.model,
                &mut self.particles,
                &self.workspace.x0,
                &mut self.contacts,
            )
        } else {
            Ok(false)
        };
        self.step += 1;
        self.end_pins(time + self.dt);
        if self.workspace.capped() {
            self.unsolved.record(self.step);
        }
        let (moved, crowded) = match phase {
            Ok(moved) => (moved, None),
            Err(crowded) => (true, Some(crowded)),
        };
        if crowded.is_none() {
            self.watch_crossings(time, report);
            self.watch_layers(report);
            self.watch_folds();
        }
        divergence::check(StepEnd {
            crowded,
            model: &self.model,
            particles: &self.particles,
            initial: &self.initial,
            start: self.workspace.start_positions(report),
            // The integrator's verdict stands unless contacts moved particles after it.
            verdict: if moved { None } else { report.verdict },
            step: self.step,
            integrator: self.integrator,
            dt: self.dt,
        })
        .and_then(|()| {
            self.watch.check(
                &self.model,
                &self.particles,
                &self.initial,
                self.step,
                self.time(),
                self.integrator,
                self.dt,
            )
        })
        .map_err(|mut d| {
            // A large step is stable at any size once solved: what is left unsolved is the
            // likelier cause.
            if self.integrator.solves_contacts() {
                let rule = self.workspace.stop_rule_of(self.integrator);
                d.solve = Some(Box::new(divergence::SolveState {
                    budget: rule.iterations,
                    capped: self.workspace.capped(),
                    tolerance: rule.tolerance,
                    unsolved: self.unsolved.steps,
                }));
            }
            d
        })
    }

    /// The crossing watch after a step from `time` (see [`watch`]): a surface found through
    /// a collider is recorded as a [`Notice`].
    fn watch_crossings(&mut self, time: f64, report: StepReport) {
        if !self.crossings.watches(&self.model) {
            return;
        }
        let vbd = self.integrator.solves_contacts();
        let mut moved = 0.0;
        if vbd {
            // Block descent's bounds keep still colliders out at any step.
            if !self.model.has_moving_colliders() {
                return;
            }
        } else {
            let Some(start) = self.workspace.start_positions(report) else {
                return;
            };
            moved = self
                .crossings
                .largest_move(start, &self.particles.x, Vec3::zeros());
            let (lo, hi) = summary::bounds(&self.particles.x);
            let sweep = self
                .model
                .colliders
                .iter()
                .map(|c| c.shape.sweep((time, time + self.dt), &lo, &hi))
                .fold(0.0, f64::max);
            if moved + sweep <= 0.5 * self.crossings.thickness {
                return;
            }
            moved += sweep;
        }
        for (collider, ids) in self.crossings.crossings(&self.model, &self.particles.x) {
            let pinned = ids.iter().find(|&&i| self.particles.is_pinned(i as usize));
            let cause = if !vbd {
                Cause::LargeStep {
                    integrator: self.integrator,
                    moved,
                    thickness: self.crossings.thickness,
                }
            } else if pinned.is_some() {
                Cause::Pinned
            } else {
                Cause::Squeezed {
                    parts: self.workspace.vbd.step_parts,
                }
            };
            self.notices.record(Notice {
                step: self.step,
                time: self.time(),
                through: Through::Collider(collider),
                particle: *pinned.unwrap_or(&ids[0]) as usize,
                cause,
            });
        }
    }

    /// The watch on layers after a large step ([`layers`], docs/physics.md §3.5): a
    /// surface found through itself or another after a step of an integrator whose contacts
    /// come after it, and that moved a surface particle relative to the others more than
    /// they can follow, is recorded as a [`Notice`].
    fn watch_layers(&mut self, report: StepReport) {
        if self.integrator.solves_contacts() || !self.model.surfaces_touch() {
            return;
        }
        let Some(start) = self.workspace.start_positions(report) else {
            return;
        };
        let (surfaces, x) = (&mut self.crossings, &self.particles.x);
        surfaces.build(&self.model);
        let moved = surfaces.largest_move(start, x, surfaces.mean_move(start, x));
        let thickness = surfaces.thickness;
        if moved <= 0.5 * thickness {
            return;
        }
        let folds = self.contacts.exclusion().folds();
        let model = &self.model;
        let self_colliding = |k: u32| model.surfaces[k as usize].self_collision;
        let lists = (&surfaces.triangles[..], &surfaces.surface[..]);
        for found in self.layers.crossings(lists, &self_colliding, x, folds) {
            let [a, b] = found.surfaces;
            // Two surfaces are named lower first, so that either passing through the other
            // is one kind of notice; the particle is on the first.
            let (through, particle) = if a == b {
                (Through::Itself(a), found.corners[0][0])
            } else if a < b {
                (Through::Surfaces(a, b), found.corners[0][0])
            } else {
                (Through::Surfaces(b, a), found.corners[1][0])
            };
            self.notices.record(Notice {
                step: self.step,
                time: self.time(),
                through,
                particle: particle as usize,
                cause: Cause::Layers {
                    integrator: self.integrator,
                    moved,
                    thickness,
                },
            });
        }
    }

    /// The watch on what self-contact skips (docs/physics.md §3.5): a surface found through
    /// itself where only a skipped pair could have let it is recorded as a [`Notice`].
    /// Looked at after every step, since nothing bounds how far a skipped pair closes; a
    /// surface with nothing skipped has nothing to look at.
    fn watch_folds(&mut self) {
        let skipped = if self.integrator.solves_contacts() {
            self.workspace.vbd.exclusion()
        } else {
            self.contacts.exclusion()
        };
        let planes = &mut self.crossings.planes;
        let Some(ids) = skipped.folds().first_through(&self.particles.x, planes) else {
            return;
        };
        let particle = ids[0] as usize;
        let Some((surface, _)) = self
            .model
            .active_surfaces()
            .find(|(_, s)| s.particles.contains(&particle))
        else {
            return;
        };
        self.notices.record(Notice {
            step: self.step,
            time: self.time(),
            through: Through::Itself(surface),
            particle,
            cause: Cause::Crease {
                reach: skipped.radius(),
                integrator: self.integrator,
            },
        });
    }

    /// The notices of steps since the last call: each the first of its kind for its
    /// collider, or for its surface through itself (see [`Notice`]). A run shows them as
    /// they come.
    pub fn take_notices(&mut self) -> Vec<Notice> {
        self.notices.take()
    }

    /// Each kind of notice's first occurrence and the steps it happened in, for a run's
    /// closing word.
    pub fn notice_tally(&self) -> &[(Notice, u64)] {
        self.notices.tally()
    }

    /// Keyframed pins at the step's start (docs/physics.md §1.2): each where its keys put it
    /// at `t`, moving at its keys' mean velocity over the step of length `dt`, which the integrators keep
    /// (a pinned particle's velocity never changes) and the springs' damping reads.
    fn start_pins(&mut self, t: f64, dt: f64) {
        let p = &mut self.particles;
        for motion in &self.model.pin_motions {
            for ((i, now), (_, next)) in motion.positions(t).zip(motion.positions(t + dt)) {
                p.x[i] = now;
                p.v[i] = (next - now) / dt;
            }
        }
    }

    /// Keyframed pins at the step's end: exactly where their keys put them at `t`, whatever
    /// the integrator did with them.
    fn end_pins(&mut self, t: f64) {
        let p = &mut self.particles;
        for motion in &self.model.pin_motions {
            for (i, at) in motion.positions(t) {
                p.x[i] = at;
            }
        }
    }

    /// The steps so far that the integrator ended at its iteration budget before its
    /// stopping rule was met (none for the explicit integrators).
    pub fn unsolved(&self) -> Unsolved {
        self.unsolved
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

    /// Whether a run whose energy grows far beyond what was supplied stops as diverged
    /// (docs/physics.md §7, "Energy from nowhere"); on by default. Off, a scheme's own energy growth
    /// can be watched to its end, as a test of the scheme does.
    pub fn watch_energy(&mut self, on: bool) {
        self.watch.enabled = on;
    }

    /// The highest-frequency estimate of the system at its current state.
    pub fn stability(&self) -> StabilityEstimate {
        StabilityEstimate::of(&self.model, &self.particles)
    }
}
