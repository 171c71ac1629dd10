//! Ctrl-C (SIGINT), SIGTERM and SIGHUP during a run: the run stops between steps, finishes
//! the files it was writing at the last complete frame, and exits with status 130
//! (128 + SIGINT).
//!
//! A second interrupt changes nothing (tools such as `timeout` and impatient users send
//! two; the run is already stopping and its files must not be lost). A third forces the
//! exit at once and removes the unfinished temporary files, for a run that does not respond.

use std::sync::atomic::{AtomicU32, Ordering};

static INTERRUPTS: AtomicU32 = AtomicU32::new(0);

/// The exit status of an interrupted run.
pub const EXIT_INTERRUPTED: u8 = 130;

/// Interrupts after which the process exits at once.
const FORCE_AFTER: u32 = 3;

pub use crate::error::Interrupted;

/// Installs the handler (see the module's documentation).
pub fn install() {
    let result = ctrlc::set_handler(|| {
        let count = INTERRUPTS.fetch_add(1, Ordering::SeqCst) + 1;
        if count == 2 {
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

/// Whether an interrupt arrived.
pub fn requested() -> bool {
    INTERRUPTS.load(Ordering::Relaxed) > 0
}

/// Between two steps of `simulation`: an [`Interrupted`] error saying where it stopped, if
/// an interrupt arrived.
pub fn check(simulation: &hooke_core::Simulation) -> Result<(), Interrupted> {
    if requested() {
        Err(Interrupted {
            step: simulation.steps(),
            time: simulation.time(),
        })
    } else {
        Ok(())
    }
}

/// Whether `e` is an interrupt.
pub fn is_interrupt(e: &crate::Error) -> bool {
    matches!(e, crate::Error::Interrupted { .. })
}
