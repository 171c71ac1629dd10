//! Progress bars on a terminal for the library's long runs and builds.

use hooke::progress::{Progress, Reporter};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

/// Draws bars on stderr when it is a terminal; otherwise says only that a large build
/// takes a while.
pub struct Bars;

struct Bar(ProgressBar);

impl Progress for Bar {
    fn set(&self, done: u64) {
        self.0.set_position(done);
    }

    fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Reporter for Bars {
    fn run(&self, scene: &str, steps: u64) -> Box<dyn Progress> {
        if !std::io::stderr().is_terminal() {
            return Box::new(Bar(ProgressBar::hidden()));
        }
        let bar = ProgressBar::new(steps);
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix} [{bar:40}] {pos}/{len} steps, {elapsed} elapsed, eta {eta}",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar.set_prefix(scene.to_string());
        Box::new(Bar(bar))
    }

    fn build(&self, what: &str) -> Box<dyn Progress> {
        if !std::io::stderr().is_terminal() {
            eprintln!("{what}; this takes a while");
            return Box::new(Bar(ProgressBar::hidden()));
        }
        let bar = ProgressBar::new_spinner();
        bar.set_message(what.to_string());
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        Box::new(Bar(bar))
    }
}
