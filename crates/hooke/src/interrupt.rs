//! Ctrl-C (SIGINT), SIGTERM and SIGHUP during a run: the run stops between steps, finishes
//! the files it was writing at the last complete frame, and exits with status 130
//! (128 + SIGINT).
//!
//! A second interrupt changes nothing (tools such as `timeout` and impatient users send
//! two; the run is already stopping and its files must not be lost). A third forces the
//! exit at once and removes the unfinished temporary files, for a run that does not respond.
//!
//! Outside a run nothing asks whether an interrupt came (reading a file, building a scene,
//! `hooke check`'s estimates): an interrupt that nothing has asked about within
//! [`ANSWER_WITHIN`], while no run's loop is under way to ask at its next step, ends the
//! process as the third does, so one Ctrl-C ends any command at any stage. No output is
//! written before a run starts, so nothing whole is lost.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::time::Duration;

static INTERRUPTS: AtomicU32 = AtomicU32::new(0);

/// Whether a poll ([`requested`]) has seen an interrupt: a run is stopping in order.
static ANSWERED: AtomicBool = AtomicBool::new(false);

/// How long an interrupt may go unseen by any poll before the process ends at once.
pub const ANSWER_WITHIN: Duration = Duration::from_millis(500);

/// Runs' loops under way, each asking between its steps: a step may take longer than
/// [`ANSWER_WITHIN`] (a large implicit step), and its run still ends in order after it.
static LOOPS: AtomicU32 = AtomicU32::new(0);

/// A job that asks for interrupts between its steps ([`requested`], [`check`]), while it
/// lives: an interrupt then waits for its next question however long a step (or a build
/// between two runs of the job) takes, and the job stops in order.
pub struct Polling;

impl Polling {
    /// Declares a polling job under way until the value is dropped.
    #[must_use = "the job polls only while the value lives"]
    pub fn start() -> Self {
        LOOPS.fetch_add(1, Ordering::SeqCst);
        Polling
    }
}

impl Drop for Polling {
    fn drop(&mut self) {
        LOOPS.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The exit status of an interrupted run.
pub const EXIT_INTERRUPTED: u8 = 130;

/// Interrupts after which the process exits at once.
const FORCE_AFTER: u32 = 3;

pub use crate::error::Interrupted;

/// Installs the handler (see the module's documentation).
pub fn install() {
    let result = ctrlc::set_handler(|| {
        let count = INTERRUPTS.fetch_add(1, Ordering::SeqCst) + 1;
        if count == 1 {
            // Waited for on a thread of its own, so that the handler stays free to take a
            // second and a third interrupt meanwhile.
            std::thread::spawn(|| {
                std::thread::sleep(ANSWER_WITHIN);
                if !ANSWERED.load(Ordering::SeqCst) && LOOPS.load(Ordering::SeqCst) == 0 {
                    crate::output::remove_pending();
                    eprintln!("interrupted");
                    std::process::exit(EXIT_INTERRUPTED as i32);
                }
            });
        } else if count == 2 {
            eprintln!(
                "stopping at the last complete frame; interrupt once more to abandon the files"
            );
        } else if count >= FORCE_AFTER {
            crate::output::remove_pending();
            eprintln!("abandoned: unfinished files removed");
            std::process::exit(EXIT_INTERRUPTED as i32);
        }
    });
    if let Err(e) = result {
        eprintln!(
            "warning: cannot handle Ctrl-C ({e}); an interrupted run may leave partial files"
        );
    }
}

/// Whether an interrupt arrived. A caller that sees one stops in order, so the process is
/// then left to do so (see the module's documentation).
pub fn requested() -> bool {
    let asked = INTERRUPTS.load(Ordering::Relaxed) > 0;
    if asked {
        ANSWERED.store(true, Ordering::SeqCst);
    }
    asked
}

/// Between two steps of `simulation`: an [`Interrupted`] error saying where it stopped, if
/// an interrupt arrived.
pub fn check(simulation: &hooke_core::Simulation) -> Result<(), Interrupted> {
    stopped_at(simulation.steps(), simulation.time())
}

/// Just after a step of `simulation`: an [`Interrupted`] error, if an interrupt arrived,
/// that counts the step as not completed (an iterative step ends early at an interrupt,
/// `Simulation::set_cancel`, so its state is not one to write or measure).
pub fn check_after_step(simulation: &hooke_core::Simulation) -> Result<(), Interrupted> {
    stopped_at(
        simulation.steps().saturating_sub(1),
        (simulation.time() - simulation.dt()).max(0.0),
    )
}

/// An [`Interrupted`] at `step` and `time` if an interrupt arrived.
fn stopped_at(step: u64, time: f64) -> Result<(), Interrupted> {
    if requested() {
        Err(Interrupted { step, time })
    } else {
        Ok(())
    }
}

/// Whether `e` is an interrupt.
pub fn is_interrupt(e: &crate::Error) -> bool {
    matches!(e, crate::Error::Interrupted { .. })
}
