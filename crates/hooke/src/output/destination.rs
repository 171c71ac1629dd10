//! Where an output path leads: a regular file (written beside itself and renamed into
//! place), or a stream — standard output (`-`), a character device such as `/dev/null`, a
//! FIFO — which is written straight through and never replaced.

use crate::error::{Result, bail_output};
use std::path::{Path, PathBuf};

/// What an output path names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Destination {
    /// `-`: the process's standard output.
    Stdout,
    /// A character device or a FIFO (or a path under `/dev` or `/proc`, such as
    /// `/dev/stdout`): opened for writing as it is, never created, renamed or removed.
    Stream(PathBuf),
    /// A regular file, existing or not: `target` is the file that is replaced, with every
    /// symbolic link leading to it resolved (so that a link stays a link).
    File {
        /// The file written.
        target: PathBuf,
    },
}

impl Destination {
    /// Whether the output is written straight through, without a temporary file.
    pub fn is_stream(&self) -> bool {
        !matches!(self, Self::File { .. })
    }
}

/// Paths under these folders are the system's own (devices, a process's descriptors):
/// written through, never replaced, whatever they resolve to. `/dev/stdout` with standard
/// output redirected to a file resolves to that file, which the shell holds open.
const SYSTEM_FOLDERS: [&str; 2] = ["/dev/", "/proc/"];

/// What `path` (given with option `flag`) leads to, or why it cannot take an output: a
/// folder, a block device, a socket, a link to nowhere, a missing folder.
///
/// ```
/// use hooke::output::destination::{Destination, destination};
/// use std::path::Path;
/// assert_eq!(destination(Path::new("-"), "--trajectory").unwrap(), Destination::Stdout);
/// assert!(destination(Path::new("/dev/null"), "--trajectory").unwrap().is_stream());
/// assert!(destination(Path::new("/"), "--trajectory").is_err());
/// ```
pub fn destination(path: &Path, flag: &str) -> Result<Destination> {
    use std::os::unix::fs::FileTypeExt;
    let shown = path.display();
    if path.as_os_str() == "-" {
        return Ok(Destination::Stdout);
    }
    let text = path.to_string_lossy();
    if text.ends_with('/') {
        bail_output!("{flag} {shown}: is a folder, expected a file name");
    }
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let system = SYSTEM_FOLDERS
        .iter()
        .any(|f| absolute.to_string_lossy().starts_with(f));
    match std::fs::metadata(path) {
        Ok(meta) => {
            let kind = meta.file_type();
            if kind.is_dir() {
                bail_output!("{flag} {shown}: is a folder, expected a file name");
            }
            if kind.is_block_device() {
                bail_output!(
                    "{flag} {shown}: is a block device; outputs go to files, character devices, \
                     FIFOs or - (standard output)"
                );
            }
            if kind.is_socket() {
                bail_output!("{flag} {shown}: is a socket, which cannot be opened for writing");
            }
            if kind.is_char_device() || kind.is_fifo() || system {
                return Ok(Destination::Stream(path.to_path_buf()));
            }
            let target = path.canonicalize().unwrap_or_else(|_| absolute.clone());
            Ok(Destination::File { target })
        }
        Err(_) if system => {
            bail_output!(
                "{flag} {shown}: no such device; hooke creates no files under /dev or /proc"
            )
        }
        Err(_) => {
            if std::fs::symlink_metadata(path).is_ok() {
                bail_output!("{flag} {shown}: is a symbolic link to nothing");
            }
            let name = path
                .file_name()
                .filter(|n| *n != "." && *n != "..")
                .ok_or_else(|| {
                    crate::Error::output(format!("{flag} {shown}: expected a file name"))
                })?;
            let parent = folder(path);
            let Ok(parent) = parent.canonicalize() else {
                bail_output!(
                    "{flag} {shown}: the folder {} does not exist",
                    parent.display()
                );
            };
            if !parent.is_dir() {
                bail_output!("{flag} {shown}: {} is not a folder", folder(path).display());
            }
            Ok(Destination::File {
                target: parent.join(name),
            })
        }
    }
}

/// The folder a file path lives in (`.` for a bare name).
pub(crate) fn folder(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}
