//! Progress of long runs and large builds. The library says what it is doing; the
//! application decides how to show it (the command line draws bars on a terminal) by
//! installing a [`Reporter`] once, as it installs the interrupt handler. Without one, long
//! builds say so on stderr and runs show nothing.

use std::sync::OnceLock;

/// Shows the progress of the library's long jobs.
pub trait Reporter: Send + Sync {
    /// A run of `steps` steps of the scene `scene` begins.
    fn run(&self, scene: &str, steps: u64) -> Box<dyn Progress>;
    /// A run of at most `steps` steps begins, which ends sooner when what it waits for
    /// happens (a drape that settles): its time left is an upper bound. The default shows
    /// it as [`Reporter::run`] does.
    fn run_until(&self, scene: &str, steps: u64) -> Box<dyn Progress> {
        self.run(scene, steps)
    }
    /// A build that takes a while begins; `what` says what is built and how large it is.
    fn build(&self, what: &str) -> Box<dyn Progress>;
    /// A run found something it promised not to do (a surface through a collider, a
    /// warning from the library's [`hooke_core::Notice`]s); `message` says what, where and
    /// why. The default prints `warning: MESSAGE` on stderr.
    fn warn(&self, message: &str) {
        eprintln!("warning: {message}");
    }
    /// A run's result may be short of what was asked, though no promise was broken (steps
    /// that ended at their solver's budget); `message` says how. The default prints
    /// `note: MESSAGE` on stderr.
    fn note(&self, message: &str) {
        eprintln!("note: {message}");
    }
}

/// One job's progress.
pub trait Progress {
    /// `done` units (steps) of the job are done.
    fn set(&self, _done: u64) {}
    /// The job ended; whatever shows it goes away.
    fn finish(&self) {}
}

/// Shows nothing.
pub(crate) struct Hidden;

impl Progress for Hidden {}

/// The reporter used until an application installs its own.
struct Plain;

impl Reporter for Plain {
    fn run(&self, _scene: &str, _steps: u64) -> Box<dyn Progress> {
        Box::new(Hidden)
    }

    fn build(&self, what: &str) -> Box<dyn Progress> {
        eprintln!("{what}; this takes a while");
        Box::new(Hidden)
    }
}

static REPORTER: OnceLock<Box<dyn Reporter>> = OnceLock::new();

/// Installs the process's reporter; a second call changes nothing and returns `false`.
pub fn install(reporter: Box<dyn Reporter>) -> bool {
    REPORTER.set(reporter).is_ok()
}

/// The installed reporter.
pub(crate) fn reporter() -> &'static dyn Reporter {
    REPORTER.get_or_init(|| Box::new(Plain)).as_ref()
}
