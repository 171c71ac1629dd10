//! The checks of `hooke report`, as `hooke.report(dir, quick=True)` runs them from Python:
//! the page and its numbers written into a folder, and the failed checks returned.
//!
//!     cargo run --release -p hooke --example report -- [DIR] [--full]

fn main() -> Result<(), hooke::Error> {
    let mut args = std::env::args().skip(1);
    let dir = std::path::PathBuf::from(args.next().unwrap_or_else(|| "report".into()));
    let quick = args.next().as_deref() != Some("--full");
    let outcome = hooke::report::write(&dir, &hooke::report::Options { quick })?;
    println!("page: {}", outcome.page.display());
    for failure in &outcome.failures {
        println!("failed: {failure}");
    }
    std::process::exit(if outcome.failures.is_empty() { 0 } else { 1 });
}
