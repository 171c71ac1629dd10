//! Progress of the library's long runs and builds: bars on a terminal, and plain lines now
//! and then when stderr is a log, so a long run never passes in silence.

use hooke::progress::{Progress, Reporter};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::cell::{Cell, RefCell};
use std::collections::VecDeque;
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

/// How far back the time-left estimate looks: a run whose steps grow slower (a collider
/// reaching the cloth, a landing) is judged by its recent steps, not by its start.
const RECENT: Duration = Duration::from_secs(20);

/// The time left of a run, from the rate of its steps over the last [`RECENT`] seconds.
#[derive(Default)]
struct TimeLeft {
    /// `(when, steps done)`, oldest first, spanning about [`RECENT`].
    samples: RefCell<VecDeque<(Instant, u64)>>,
}

impl TimeLeft {
    /// Records that `done` steps are done now, and says about how many seconds the
    /// remaining `total - done` take at the recent rate (`None` before there is one).
    fn after(&self, now: Instant, done: u64, total: u64) -> Option<f64> {
        let mut samples = self.samples.borrow_mut();
        samples.push_back((now, done));
        while samples.len() > 2 && now.duration_since(samples[1].0) >= RECENT {
            samples.pop_front();
        }
        let (t0, d0) = *samples.front()?;
        let seconds = now.duration_since(t0).as_secs_f64();
        let steps = done.saturating_sub(d0);
        (steps > 0 && seconds > 0.0)
            .then(|| total.saturating_sub(done) as f64 * seconds / steps as f64)
    }
}

/// Seconds as a person reads them: `42 s`, `3 min 5 s`, `2 h 10 min`.
fn human(seconds: f64) -> String {
    let s = seconds.round() as u64;
    if s < 60 {
        format!("{s} s")
    } else if s < 3600 {
        format!("{} min {} s", s / 60, s % 60)
    } else {
        format!("{} h {} min", s / 3600, (s % 3600) / 60)
    }
}

/// Draws bars on stderr when it is a terminal; otherwise writes a line of progress every
/// ten seconds of a run, and says that a large build takes a while.
pub struct Bars;

/// A bar, drawn once its run has taken [`SHOW_AFTER`].
struct Bar {
    bar: ProgressBar,
    started: Instant,
    shown: Cell<bool>,
    left: TimeLeft,
    /// Whether the run may end before its last step (then its time left is at most).
    until: bool,
}

impl Progress for Bar {
    fn set(&self, done: u64) {
        self.bar.set_position(done);
        if let Some(total) = self.bar.length()
            && let Some(left) = self.left.after(Instant::now(), done, total)
        {
            let about = if self.until { "at most" } else { "about" };
            self.bar
                .set_message(format!("{about} {} left", human(left)));
        }
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
    left: TimeLeft,
    /// Whether the run may end before its last step.
    until: bool,
}

impl Progress for Lines {
    fn set(&self, done: u64) {
        let now = Instant::now();
        let left = self.left.after(now, done, self.steps);
        if now.duration_since(self.last.get()) < self.every {
            return;
        }
        self.last.set(now);
        let elapsed = now.duration_since(self.started).as_secs_f64();
        let share = done as f64 / self.steps.max(1) as f64;
        let (of, about) = if self.until {
            ("at most ", "at most")
        } else {
            ("", "about")
        };
        let left = left.map_or_else(String::new, |s| format!(", {about} {} left", human(s)));
        eprintln!(
            "{}: step {done} of {of}{} ({:.0} %), {elapsed:.0} s elapsed{left}",
            self.scene,
            self.steps,
            100.0 * share
        );
    }
}

impl Bars {
    /// A run's progress: `until`, it may end before its last step.
    fn progress(scene: &str, steps: u64, until: bool) -> Box<dyn Progress> {
        if !std::io::stderr().is_terminal() {
            let now = Instant::now();
            return Box::new(Lines {
                scene: scene.to_string(),
                steps,
                every: line_every(),
                started: now,
                last: Cell::new(now),
                left: TimeLeft::default(),
                until,
            });
        }
        let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::hidden());
        let template = if until {
            "{prefix} [{bar:40}] {pos}/at most {len} steps, {elapsed} elapsed, {msg}"
        } else {
            "{prefix} [{bar:40}] {pos}/{len} steps, {elapsed} elapsed, {msg}"
        };
        bar.set_style(
            ProgressStyle::with_template(template)
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_prefix(scene.to_string());
        Box::new(Bar {
            bar,
            started: Instant::now(),
            shown: Cell::new(false),
            left: TimeLeft::default(),
            until,
        })
    }
}

impl Reporter for Bars {
    fn run(&self, scene: &str, steps: u64) -> Box<dyn Progress> {
        Self::progress(scene, steps, false)
    }

    fn run_until(&self, scene: &str, steps: u64) -> Box<dyn Progress> {
        Self::progress(scene, steps, true)
    }

    fn build(&self, what: &str) -> Box<dyn Progress> {
        if !std::io::stderr().is_terminal() {
            eprintln!("{what}; this takes a while");
            return Box::new(Bar {
                bar: ProgressBar::hidden(),
                started: Instant::now(),
                shown: Cell::new(true),
                left: TimeLeft::default(),
                until: false,
            });
        }
        let bar = ProgressBar::new_spinner();
        bar.set_message(what.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        Box::new(Bar {
            bar,
            started: Instant::now(),
            shown: Cell::new(true),
            left: TimeLeft::default(),
            until: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps that take 10 ms for a minute, then 1 s: a minute after the change, the time
    /// left is read from the slow steps, not from the whole run's average.
    #[test]
    fn the_time_left_follows_the_recent_steps() {
        let left = TimeLeft::default();
        let start = Instant::now();
        let mut now = start;
        let mut done = 0;
        let mut said = None;
        for _ in 0..6000 {
            now += Duration::from_millis(10);
            done += 1;
            said = left.after(now, done, 10_000);
        }
        assert!((said.unwrap() - 40.0).abs() < 1.0, "{said:?}");
        for _ in 0..60 {
            now += Duration::from_secs(1);
            done += 1;
            said = left.after(now, done, 10_000);
        }
        // 3940 steps left at 1 s each.
        let s = said.unwrap();
        assert!((s / 3940.0 - 1.0).abs() < 0.05, "{s}");
        assert_eq!(human(65.0), "1 min 5 s");
        assert_eq!(human(7300.0), "2 h 1 min");
    }
}
