//! Ctrl-C (SIGINT) during a run: the run stops between steps, finishes the files it was
//! writing at the last complete frame, and exits with status 130 (128 + SIGINT).

use std::sync::atomic::{AtomicBool, Ordering};

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// The exit status of an interrupted run.
pub const EXIT_INTERRUPTED: u8 = 130;

/// The run was interrupted: carried as an error so that every caller stops the same way.
#[derive(Debug, thiserror::Error)]
#[error("interrupted at step {step} (t = {time} s)")]
pub struct Interrupted {
    /// Steps completed.
    pub step: u64,
    /// Simulated time reached, seconds.
    pub time: f64,
}

/// Installs the handler: the first Ctrl-C asks the run to stop; a second one, for a run that
/// does not respond, exits at once.
pub fn install() {
    let result = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(EXIT_INTERRUPTED as i32);
        }
    });
    if let Err(e) = result {
        eprintln!(
            "warning: cannot handle Ctrl-C ({e}); an interrupted run may leave partial files"
        );
    }
}

/// Whether Ctrl-C was pressed.
pub fn requested() -> bool {
    INTERRUPTED.load(Ordering::Relaxed)
}
