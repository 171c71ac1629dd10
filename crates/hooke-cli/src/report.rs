//! `hooke report DIR`: the checks that show the physics is right, run here and written as
//! a page (see `hooke::report`); exits with status 1 when a check failed.

use anyhow::Result;
use std::path::Path;
use std::process::ExitCode;

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
