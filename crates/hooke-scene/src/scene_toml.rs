//! The TOML scene format, whose keys are the types of `spec.rs`: reading with
//! line-numbered errors and writing, as `world.rs` reads the course's `.w` worlds.

use crate::spec::SceneSpec;
use std::path::{Path, PathBuf};

/// Why a scene file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read scene {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The text is not a valid scene; the message holds the line, the column and what was
    /// expected.
    #[error("{path}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// toml's message, with line and column.
        message: String,
    },
}

/// Parses scene text; `name` names it in errors.
pub fn parse_scene(text: &str, name: impl AsRef<Path>) -> Result<SceneSpec, SceneError> {
    toml::from_str(text).map_err(|e| SceneError::Syntax {
        path: name.as_ref().to_path_buf(),
        message: match e.span() {
            Some(span) => locate(text, span.start, e.message()),
            None => e.message().trim_end().to_string(),
        },
    })
}

/// Lines longer than this that hold an array of arrays are written one inner array per line.
const LONG_LINE: usize = 120;

/// Breaks `key = [[…], […], …]` lines longer than [`LONG_LINE`] after each inner array,
/// so that a world's force field or a points body reads as one vector per line (TOML allows
/// newlines inside arrays; the values are unchanged).
fn wrap_long_arrays(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + text.len() / 16);
    for line in text.lines() {
        let Some(at) = line.find(" = [[").filter(|_| line.len() > LONG_LINE) else {
            out.push_str(line);
            out.push('\n');
            continue;
        };
        let (head, array) = line.split_at(at + 4);
        out.push_str(head);
        out.push('\n');
        // Inner arrays hold numbers only, so brackets and strings need no care here.
        let inner = &array[..array.len() - 1];
        for item in inner.split("], ") {
            let item = item.trim_end_matches(']');
            out.push_str("    ");
            out.push_str(item);
            out.push_str("],\n");
        }
        out.push_str("]\n");
    }
    out
}

/// Characters of the offending line shown on either side of the error.
const EXCERPT_HALF: usize = 40;

/// `line L, column C: message` and an excerpt of the line with a caret: at most about
/// 80 characters of it, however long the line (toml's own rendering echoes the whole line).
fn locate(text: &str, offset: usize, message: &str) -> String {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line_no = before.matches('\n').count() + 1;
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let line: Vec<char> = text[line_start..line_end]
        .trim_end_matches('\r')
        .chars()
        .collect();
    let column = text[line_start..offset].chars().count();
    let from = column.saturating_sub(EXCERPT_HALF);
    let to = (column + EXCERPT_HALF).min(line.len());
    let mut excerpt: String = line[from..to.max(from)].iter().collect();
    let mut caret = column - from;
    if from > 0 {
        excerpt.insert(0, '…');
        caret += 1;
    }
    if to < line.len() {
        excerpt.push('…');
    }
    format!(
        "line {line_no}, column {}: {}\n  | {excerpt}\n  | {}^",
        column + 1,
        message.trim_end(),
        " ".repeat(caret)
    )
}

/// Reads a scene file.
pub fn load_scene(path: &Path) -> Result<SceneSpec, SceneError> {
    let text = hooke_core::text::read_text(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_scene(&text, path)
}

/// The scene as TOML text, with a header naming it; [`parse_scene`] reads it back equal.
pub fn to_toml(spec: &SceneSpec) -> String {
    let body = wrap_long_arrays(&toml::to_string(spec).expect("scene specs always serialise"));
    format!(
        "# Hooke scene '{}': {}\n# Format: see docs/scenes.md (the reference is crates/hooke-scene/src/spec.rs).\n\n{body}",
        spec.name, spec.description
    )
}
