//! Progress of the library's long runs and builds: bars on a terminal, and plain lines now
//! and then when stderr is a log, so a long run never passes in silence.

use hooke::progress::{Progress, Reporter};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::cell::Cell;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// A run that has taken this long shows its bar (shorter runs never draw one).
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// Between two lines of a run's progress in a log, unless `HOOKE_PROGRESS_SECONDS` says
/// otherwise.
const LINE_EVERY: Duration = Duration::from_secs(10);

/// The time between two lines of progress in a log: [`LINE_EVERY`], or the seconds in
/// `HOOKE_PROGRESS_SECONDS` (0: after every step).
fn line_every() -> Duration {
    std::env::var("HOOKE_PROGRESS_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
        .map_or(LINE_EVERY, Duration::from_secs_f64)
}

/// Draws bars on stderr when it is a terminal; otherwise writes a line of progress every
/// ten seconds of a run, and says that a large build takes a while.
pub struct Bars;

/// A bar, drawn once its run has taken [`SHOW_AFTER`].
struct Bar {
    bar: ProgressBar,
    started: Instant,
    shown: Cell<bool>,
}

impl Progress for Bar {
    fn set(&self, done: u64) {
        self.bar.set_position(done);
        if !self.shown.get() && self.started.elapsed() >= SHOW_AFTER {
            self.shown.set(true);
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// A run's progress as a line now and then, for a log.
struct Lines {
    scene: String,
    steps: u64,
    every: Duration,
    started: Instant,
    last: Cell<Instant>,
}

impl Progress for Lines {
    fn set(&self, done: u64) {
        let now = Instant::now();
        if now.duration_since(self.last.get()) < self.every {
            return;
        }
        self.last.set(now);
        let elapsed = now.duration_since(self.started).as_secs_f64();
        let share = done as f64 / self.steps.max(1) as f64;
        let left = if share > 0.0 {
            format!(", about {:.0} s left", elapsed * (1.0 - share) / share)
        } else {
            String::new()
        };
        eprintln!(
            "{}: step {done} of {} ({:.0} %), {elapsed:.0} s elapsed{left}",
            self.scene,
            self.steps,
            100.0 * share
        );
    }
}

impl Reporter for Bars {
    fn run(&self, scene: &str, steps: u64) -> Box<dyn Progress> {
        if !std::io::stderr().is_terminal() {
            let now = Instant::now();
            return Box::new(Lines {
                scene: scene.to_string(),
                steps,
                every: line_every(),
                started: now,
                last: Cell::new(now),
            });
        }
        let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix} [{bar:40}] {pos}/{len} steps, {elapsed} elapsed, eta {eta}",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar.set_prefix(scene.to_string());
        Box::new(Bar {
            bar,
            started: Instant::now(),
            shown: Cell::new(false),
        })
    }

    fn build(&self, what: &str) -> Box<dyn Progress> {
        if !std::io::stderr().is_terminal() {
            eprintln!("{what}; this takes a while");
            return Box::new(Bar {
                bar: ProgressBar::hidden(),
                started: Instant::now(),
                shown: Cell::new(true),
            });
        }
        let bar = ProgressBar::new_spinner();
        bar.set_message(what.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        Box::new(Bar {
            bar,
            started: Instant::now(),
            shown: Cell::new(true),
        })
    }
}
