//! Worker threads: how many a command or a Python simulation may start. Results are the
//! same bits on any count, so more threads than cores only cost; a count in the thousands
//! (a typo, an extra zero) would start that many OS threads and stall the machine.

use crate::error::{Context, Result, bail_input};

/// The most threads any machine is given.
pub const MAX_THREADS: usize = 256;

/// The most threads this machine is given: four per core, at most [`MAX_THREADS`].
pub fn max_threads() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    cores.saturating_mul(4).min(MAX_THREADS)
}

/// `requested` threads, given as `name` (`--threads`, `threads`), if it is from 1 to
/// [`max_threads`].
///
/// ```
/// use hooke::threads::{checked, max_threads};
/// assert_eq!(checked(1, "--threads").unwrap(), 1);
/// assert!(checked(0, "--threads").is_err());
/// assert!(checked(max_threads() + 1, "--threads").is_err());
/// ```
pub fn checked(requested: usize, name: &str) -> Result<usize> {
    let max = max_threads();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if requested == 0 {
        bail_input!("{name}: expected at least 1 thread");
    }
    if requested > max {
        bail_input!(
            "{name} {requested}: expected at most {max} threads on this machine ({cores} \
             core{}; four per core, {MAX_THREADS} at most): results are the same on any count, \
             and more threads than cores only slow the run down",
            if cores == 1 { "" } else { "s" }
        );
    }
    Ok(requested)
}

/// The thread count rayon's `RAYON_NUM_THREADS` asks for, checked like [`checked`];
/// `None` when it is unset, empty or 0 (rayon's own default then: one per core).
pub fn from_environment() -> Result<Option<usize>> {
    let Ok(text) = std::env::var("RAYON_NUM_THREADS") else {
        return Ok(None);
    };
    match text.trim().parse::<usize>() {
        Ok(0) => Ok(None),
        Ok(n) => checked(n, "RAYON_NUM_THREADS").map(Some),
        Err(_) if text.trim().is_empty() => Ok(None),
        Err(_) => bail_input!("RAYON_NUM_THREADS={text}: expected a whole number of threads"),
    }
}

/// The workers a pool gets: `threads` (given as `name`), or the environment's, checked
/// like [`checked`]; `None`: one per core.
pub fn count(threads: Option<usize>, name: &str) -> Result<Option<usize>> {
    match threads {
        Some(n) => checked(n, name).map(Some),
        None => from_environment(),
    }
}

/// A pool of `count` workers (`None`: one per core), as [`count`] gives.
pub fn build(count: Option<usize>) -> Result<rayon::ThreadPool> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = count {
        builder = builder.num_threads(n);
    }
    builder.build().context("cannot start the worker threads")
}

/// A pool of `threads` workers (given as `name`), or of the environment's or one per core
/// when `None`; refused beyond [`max_threads`].
pub fn pool(threads: Option<usize>, name: &str) -> Result<rayon::ThreadPool> {
    build(count(threads, name)?)
}
