//! `hooke report DIR`: the checks that show the physics is right, run here and written as
//! a page (see `hooke::report`). Exit status: 0 when every check passed, 1 when a check
//! failed (the page says which), 2 when the report could not run (a bad folder, a refused
//! output, an unreadable environment, an error while writing); 130 when interrupted.

use anyhow::Result;
use std::path::Path;
use std::process::ExitCode;

/// The exit status of a report that could not run, told apart from a failed check (1).
pub const COULD_NOT_RUN: u8 = 2;

pub fn report(dir: &Path, quick: bool) -> Result<ExitCode> {
    let started = std::time::Instant::now();
    let outcome = hooke::report::write(dir, &hooke::report::Options { quick })?;
    eprintln!(
        "report: {} ({:.0} s)",
        outcome.page.display(),
        started.elapsed().as_secs_f64()
    );
    if outcome.failures.is_empty() {
        eprintln!("every check passed");
        return Ok(ExitCode::SUCCESS);
    }
    eprintln!("{} checks failed:", outcome.failures.len());
    for f in &outcome.failures {
        eprintln!("  {f}");
    }
    Ok(ExitCode::FAILURE)
}
