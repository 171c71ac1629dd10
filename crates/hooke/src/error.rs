//! The one error every fallible call of this crate returns: a caller matches its variant to
//! tell a bad file from a divergence, a refused output or an interrupt, and prints it to
//! say all of it (what, where, why) on one line.

use hooke_collide::MeshError;
use hooke_core::Divergence;
use hooke_scene::world::{InvalidWorld, WorldError};
use hooke_scene::{BuildError, SceneError};
use std::fmt::Display;
use std::path::PathBuf;

/// The run was interrupted: carried as an error so that every caller stops the same way.
#[derive(Debug, thiserror::Error)]
#[error("interrupted at step {step} (t = {} s)", hooke_core::Approx(*.time))]
pub struct Interrupted {
    /// Steps completed.
    pub step: u64,
    /// Simulated time reached, seconds.
    pub time: f64,
}

/// What went wrong in a call of this crate. Its text is complete: the context a caller
/// added (`scene 'cloth-table'`), then the cause, then the cause's causes, joined by `: `.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A scene, world, mesh, option or environment variable is not what was expected.
    #[error("{message}")]
    Input {
        /// The whole message.
        message: String,
        /// Where the bad input is, as far as it is known.
        location: Location,
    },
    /// The simulation diverged; the files written up to the last finite frame are kept.
    #[error("{message}")]
    Diverged {
        /// The whole message.
        message: String,
        /// Where and how it diverged.
        divergence: Divergence,
    },
    /// An output could not be written, or was refused because it would replace something
    /// it must not (an input, a device, a folder).
    #[error("{message}")]
    Output {
        /// The whole message.
        message: String,
    },
    /// Ctrl-C, SIGTERM or SIGHUP stopped the run between two steps.
    #[error("{message}")]
    Interrupted {
        /// The whole message.
        message: String,
        /// The step and time it stopped at.
        at: Interrupted,
    },
}

/// Where a bad input is: each part that is known.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    /// The file (scene, world, mesh).
    pub file: Option<PathBuf>,
    /// Its 1-based line.
    pub line: Option<usize>,
    /// The scene key, e.g. `body[1].pins[3]`.
    pub key: Option<String>,
}

/// This crate's results.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// A bad input known only by its message.
    pub(crate) fn input(message: impl Into<String>) -> Self {
        Self::Input {
            message: message.into(),
            location: Location::default(),
        }
    }

    /// A refused or failed output.
    pub(crate) fn output(message: impl Into<String>) -> Self {
        Self::Output {
            message: message.into(),
        }
    }

    /// The whole message.
    pub fn message(&self) -> &str {
        match self {
            Self::Input { message, .. }
            | Self::Diverged { message, .. }
            | Self::Output { message }
            | Self::Interrupted { message, .. } => message,
        }
    }

    /// The same error with `context: ` in front of its message.
    pub fn context(mut self, context: impl Display) -> Self {
        let message = match &mut self {
            Self::Input { message, .. }
            | Self::Diverged { message, .. }
            | Self::Output { message }
            | Self::Interrupted { message, .. } => message,
        };
        *message = format!("{context}: {message}");
        self
    }
}

/// `e` and its causes, joined by `: ` as the command line prints them.
fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

impl From<Divergence> for Error {
    fn from(divergence: Divergence) -> Self {
        Self::Diverged {
            message: chain(&divergence),
            divergence,
        }
    }
}

impl From<Interrupted> for Error {
    fn from(at: Interrupted) -> Self {
        Self::Interrupted {
            message: at.to_string(),
            at,
        }
    }
}

/// An OS error here is an output's: inputs are read by the scene crate, whose errors name
/// their files.
impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Self::output(chain(&e))
    }
}

/// Formatting into a `String` fails only when a value's own formatting does; it is part
/// of writing an output.
impl From<std::fmt::Error> for Error {
    fn from(e: std::fmt::Error) -> Self {
        Self::output(e.to_string())
    }
}

/// Errors of the encoders and of sizes that do not fit a format: all part of writing an
/// output.
macro_rules! output_errors {
    ($($t:ty),*) => {$(
        impl From<$t> for Error {
            fn from(e: $t) -> Self {
                Self::output(chain(&e))
            }
        }
    )*};
}

output_errors!(
    image::ImageError,
    gif::EncodingError,
    std::num::TryFromIntError
);

/// The worker threads asked for (`--threads`, `RAYON_NUM_THREADS`) could not be started.
impl From<rayon::ThreadPoolBuildError> for Error {
    fn from(e: rayon::ThreadPoolBuildError) -> Self {
        Self::input(chain(&e))
    }
}

impl From<InvalidWorld> for Error {
    fn from(e: InvalidWorld) -> Self {
        Self::Input {
            message: chain(&e),
            location: Location {
                key: Some(e.key.clone()),
                ..Location::default()
            },
        }
    }
}

impl From<MeshError> for Error {
    fn from(e: MeshError) -> Self {
        let location = mesh_location(&e);
        Self::Input {
            message: chain(&e),
            location,
        }
    }
}

fn mesh_location(e: &MeshError) -> Location {
    let (file, line) = match e {
        MeshError::Io { path, .. } | MeshError::Obj { path, .. } => (path.clone(), None),
        MeshError::Line { path, line, .. } => (path.clone(), Some(*line)),
        other => return Location::from_text(&other.to_string()),
    };
    Location {
        file: Some(file),
        line,
        key: None,
    }
}

impl Location {
    /// The `FILE:LINE:` a message starts with, when it does.
    fn from_text(text: &str) -> Self {
        let mut parts = text.splitn(3, ':');
        let file = parts.next().filter(|f| !f.is_empty() && !f.contains(' '));
        let line = parts.next().and_then(|l| l.trim().parse().ok());
        Self {
            file: file.map(PathBuf::from),
            line,
            key: None,
        }
    }
}

impl From<SceneError> for Error {
    fn from(e: SceneError) -> Self {
        let location = match &e {
            SceneError::Io { path, .. } => Location {
                file: Some(path.clone()),
                ..Location::default()
            },
            SceneError::Syntax { path, message } => Location {
                file: Some(path.clone()),
                // The reader's messages start "line N, column M: ".
                line: message
                    .strip_prefix("line ")
                    .and_then(|rest| rest.split(|c: char| !c.is_ascii_digit()).next())
                    .and_then(|n| n.parse().ok()),
                key: None,
            },
        };
        Self::Input {
            message: chain(&e),
            location,
        }
    }
}

impl From<WorldError> for Error {
    fn from(e: WorldError) -> Self {
        let location = match &e {
            WorldError::Io { path, .. } => Location {
                file: Some(path.clone()),
                ..Location::default()
            },
            WorldError::Format { path, line, .. } => Location {
                file: Some(path.clone()),
                line: Some(*line),
                key: None,
            },
        };
        Self::Input {
            message: chain(&e),
            location,
        }
    }
}

impl From<BuildError> for Error {
    fn from(e: BuildError) -> Self {
        let location = match &e {
            BuildError::Invalid { key, .. } => Location {
                key: Some(key.clone()),
                ..Location::default()
            },
            BuildError::Mesh { key, source } => Location {
                key: Some(key.clone()),
                ..mesh_location(source)
            },
        };
        Self::Input {
            message: chain(&e),
            location,
        }
    }
}

/// Adding what was being done to an error on its way up, as `anyhow::Context` does, keeping
/// its variant.
pub trait Context<T> {
    /// `context: ` in front of the error's message.
    fn context(self, context: impl Display) -> Result<T>;
    /// [`Context::context`] with a message made only when there is an error.
    fn with_context<D: Display>(self, context: impl FnOnce() -> D) -> Result<T>;
}

impl<T, E: Into<Error>> Context<T> for std::result::Result<T, E> {
    fn context(self, context: impl Display) -> Result<T> {
        self.map_err(|e| e.into().context(context))
    }

    fn with_context<D: Display>(self, context: impl FnOnce() -> D) -> Result<T> {
        self.map_err(|e| e.into().context(context()))
    }
}

/// A missing value is a bad input: the name looked up is not there.
impl<T> Context<T> for Option<T> {
    fn context(self, context: impl Display) -> Result<T> {
        self.ok_or_else(|| Error::input(context.to_string()))
    }

    fn with_context<D: Display>(self, context: impl FnOnce() -> D) -> Result<T> {
        self.ok_or_else(|| Error::input(context().to_string()))
    }
}

/// Returns an [`Error::Input`] made from a format string.
macro_rules! bail_input {
    ($($t:tt)*) => {
        return Err($crate::Error::input(format!($($t)*)))
    };
}

/// Returns an [`Error::Output`] made from a format string.
macro_rules! bail_output {
    ($($t:tt)*) => {
        return Err($crate::Error::output(format!($($t)*)))
    };
}

pub(crate) use {bail_input, bail_output};

#[cfg(test)]
mod tests {
    use super::*;

    /// The time a run stopped at is said to four digits, not as the step count times a
    /// step that no binary fraction holds (`0.31666666666666665`).
    #[test]
    fn an_interruption_says_its_time_without_rounding_noise() {
        let e = Interrupted {
            step: 19,
            time: 19.0 * (1.0 / 60.0),
        };
        assert_eq!(e.to_string(), "interrupted at step 19 (t = 0.3167 s)");
    }

    #[test]
    fn context_goes_in_front_and_keeps_the_variant() {
        let e = Error::input("expected a number").context("scene 'x'");
        assert_eq!(e.to_string(), "scene 'x': expected a number");
        assert!(matches!(e, Error::Input { .. }));
    }

    #[test]
    fn a_scene_syntax_error_keeps_its_file_and_line() {
        let text = "name = \"bad\"\n[simulation]\ndt = \"fast\"\n";
        let e: Error = hooke_scene::parse_scene(text, "bad.toml")
            .unwrap_err()
            .into();
        let Error::Input { location, .. } = e else {
            panic!("not an input error")
        };
        assert_eq!(location.file, Some(PathBuf::from("bad.toml")));
        assert_eq!(location.line, Some(3));
    }

    #[test]
    fn a_world_error_keeps_its_file_and_line() {
        let e: Error = WorldError::Format {
            path: "a.w".into(),
            line: 7,
            message: "expected 3 numbers".into(),
        }
        .into();
        let Error::Input { location, message } = e else {
            panic!("not an input error")
        };
        assert_eq!(location.file, Some(PathBuf::from("a.w")));
        assert_eq!(location.line, Some(7));
        assert_eq!(message, "a.w:7: expected 3 numbers");
    }
}
