//! An output file that appears whole or not at all, or a stream written straight through.
//!
//! A regular file is written to a hidden temporary file beside its target
//! (`.hooke-PID-N.tmp`: short, whatever the target's name) and renamed over the target on
//! [`OutputFile::commit`]. A stream (`-`, a character device, a FIFO) is opened as it is and
//! only flushed: it is never created, renamed or removed. Temporary files left by a process
//! that no longer runs (one killed with SIGKILL) are removed the first time this process
//! writes into the same folder.

use super::destination::{Destination, destination, folder};
use crate::error::{Context, Result};
use std::collections::HashSet;
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// Temporary files being written, so that an exit forced by a repeated interrupt can still
/// remove them (see [`crate::interrupt`]).
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Folders already cleared of dead processes' temporary files by this process.
static SWEPT: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);

/// The number of this process's next temporary file.
static NEXT: AtomicU64 = AtomicU64::new(0);

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    // A panic while holding the lock leaves plain data behind: still usable.
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary file still being written. For the forced exit only: the files'
/// owners are abandoned with them.
pub fn remove_pending() {
    for temp in lock(&PENDING).drain(..) {
        let _ = std::fs::remove_file(temp);
    }
}

/// A fresh temporary file name in `dir`: hidden, named after this process.
pub(crate) fn temp_in(dir: &Path) -> PathBuf {
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    dir.join(format!(".hooke-{}-{n}.tmp", std::process::id()))
}

/// The process that wrote temporary file `name`, if `name` is one of ours: the current
/// `.hooke-PID-N.tmp` and the earlier `.TARGET.PID.tmp`.
fn writer_of(name: &str) -> Option<u32> {
    let inner = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let pid = match inner.strip_prefix("hooke-") {
        Some(rest) if rest.split('-').count() == 2 => rest.split('-').next()?,
        _ => inner.rsplit('.').next()?,
    };
    pid.parse().ok()
}

/// Whether process `pid` still runs; `true` where that cannot be told (no `/proc`).
fn running(pid: u32) -> bool {
    !Path::new("/proc/self").exists() || Path::new("/proc").join(pid.to_string()).exists()
}

/// Removes, once per folder and process, the temporary files of processes that no longer
/// run. Returns how many were removed.
fn sweep(dir: &Path) -> usize {
    let key = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    if !lock(&SWEPT).get_or_insert_with(HashSet::new).insert(key) {
        return 0;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let dead = writer_of(&name.to_string_lossy())
            .is_some_and(|pid| pid != std::process::id() && !running(pid));
        // A link or a second name planted under a temporary's name is left alone.
        if dead && entry.metadata().is_ok_and(|m| super::named::is_plain(&m)) {
            removed += usize::from(std::fs::remove_file(entry.path()).is_ok());
        }
    }
    removed
}

/// Where the bytes go.
pub enum Sink {
    /// A file: the temporary one, or a device or FIFO opened as it is.
    File(File),
    /// Standard output.
    Stdout(std::io::Stdout),
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self {
            Self::File(f) => f.write(buf),
            Self::Stdout(s) => s.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            Self::File(f) => f.flush(),
            Self::Stdout(s) => s.flush(),
        }
    }
}

/// Seeking works on files; on a pipe or standard output it fails with the system's error.
impl Seek for Sink {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        match self {
            Self::File(f) => f.seek(pos),
            Self::Stdout(_) => Err(std::io::Error::new(
                std::io::ErrorKind::Unsupported,
                "standard output cannot seek",
            )),
        }
    }
}

/// A file being written. A regular file replaces its target only on
/// [`OutputFile::commit`], and dropped without a commit its temporary file is removed; a
/// stream is written as the bytes come.
pub struct OutputFile {
    /// The path as given, for messages.
    shown: PathBuf,
    /// The temporary file and the target it replaces; `None` for a stream.
    rename: Option<(PathBuf, Option<PathBuf>)>,
    writer: Option<BufWriter<Sink>>,
}

impl OutputFile {
    /// Starts writing `target`.
    pub fn create(target: &Path) -> Result<Self> {
        let shown = target.to_path_buf();
        match destination(target, "cannot write")? {
            Destination::Stdout => Ok(Self {
                shown,
                rename: None,
                writer: Some(BufWriter::new(Sink::Stdout(std::io::stdout()))),
            }),
            Destination::Stream(path) => {
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(&path)
                    .with_context(|| format!("cannot open {} for writing", path.display()))?;
                Ok(Self {
                    shown,
                    rename: None,
                    writer: Some(BufWriter::new(Sink::File(file))),
                })
            }
            Destination::File { target: resolved } => {
                Self::temporary(folder(&resolved), shown, Some(resolved.clone()))
            }
        }
    }

    /// Starts writing `path`, a name Hooke chose inside a folder it writes (given with
    /// option `flag`): refused unless nothing is there or a plain file of this user's (see
    /// [`super::named`]); the file is renamed over that name itself, never through a link.
    pub fn create_named(path: &Path, flag: &str) -> Result<Self> {
        super::named::check_named(path, flag)?;
        Self::temporary(folder(path), path.to_path_buf(), Some(path.to_path_buf()))
    }

    /// A scratch file for an output to `near`: hidden beside it (or in the system's
    /// temporary folder when `near` is a stream), never committed, removed when dropped.
    pub fn scratch(near: &Path) -> Result<Self> {
        let dir = match destination(near, "cannot write")? {
            Destination::File { target } => folder(&target).to_path_buf(),
            _ => std::env::temp_dir(),
        };
        Self::temporary(&dir, near.to_path_buf(), None)
    }

    fn temporary(dir: &Path, shown: PathBuf, target: Option<PathBuf>) -> Result<Self> {
        sweep(dir);
        let temp = temp_in(dir);
        let file = super::named::create_new(&temp).with_context(|| {
            format!(
                "cannot write {}: cannot create a file in {}",
                shown.display(),
                dir.display()
            )
        })?;
        lock(&PENDING).push(temp.clone());
        Ok(Self {
            shown,
            rename: Some((temp, target)),
            writer: Some(BufWriter::new(Sink::File(file))),
        })
    }

    /// The writer.
    pub fn writer(&mut self) -> &mut BufWriter<Sink> {
        self.writer.as_mut().expect("writer present until commit")
    }

    /// What was written so far, read from the start: for a scratch file that is copied into
    /// another and then dropped (which removes it).
    pub fn read_back(&mut self) -> Result<File> {
        let shown = self.shown.display().to_string();
        self.writer()
            .flush()
            .with_context(|| format!("cannot write {shown}"))?;
        match self.rename.as_ref() {
            Some((temp, _)) => {
                File::open(temp).with_context(|| format!("cannot read back {}", temp.display()))
            }
            None => crate::error::bail_output!("{shown} is a stream: it cannot be read back"),
        }
    }

    /// Flushes, syncs and renames the file into place (a stream is flushed).
    pub fn commit(mut self) -> Result<()> {
        let writer = self.writer.take().expect("commit once");
        let shown = self.shown.display().to_string();
        let result = (|| {
            let sink = writer
                .into_inner()
                .map_err(|e| e.into_error())
                .with_context(|| format!("cannot write {shown}"))?;
            let Some((temp, target)) = &self.rename else {
                let mut sink = sink;
                return sink
                    .flush()
                    .with_context(|| format!("cannot write {shown}"));
            };
            let target = target.as_ref().expect("scratch files are not committed");
            if let Sink::File(file) = &sink {
                file.sync_all()
                    .with_context(|| format!("cannot write {shown}"))?;
            }
            std::fs::rename(temp, target).with_context(|| format!("cannot move {shown} into place"))
        })();
        if let Some((temp, _)) = &self.rename {
            if result.is_err() {
                let _ = std::fs::remove_file(temp);
            }
            lock(&PENDING).retain(|p| p != temp);
        }
        result
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        if self.writer.take().is_some()
            && let Some((temp, _)) = &self.rename
        {
            let _ = std::fs::remove_file(temp);
            lock(&PENDING).retain(|p| p != temp);
        }
    }
}

/// Writes go to the temporary file (or the stream), so an encoder can own an `OutputFile`
/// and hand it back for the commit.
impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer().write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer().flush()
    }
}

/// Writes a whole file atomically (or a stream at once).
pub fn write_atomic(target: &Path, bytes: &[u8]) -> Result<()> {
    write_all(OutputFile::create(target)?, target, bytes)
}

/// Writes a whole file atomically at `path`, a name Hooke chose inside a folder it writes
/// (see [`OutputFile::create_named`]).
pub fn write_named(path: &Path, flag: &str, bytes: &[u8]) -> Result<()> {
    write_all(OutputFile::create_named(path, flag)?, path, bytes)
}

fn write_all(mut f: OutputFile, target: &Path, bytes: &[u8]) -> Result<()> {
    f.writer()
        .write_all(bytes)
        .with_context(|| format!("cannot write {}", target.display()))?;
    f.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_tell_their_writer() {
        assert_eq!(writer_of(".hooke-123-7.tmp"), Some(123));
        assert_eq!(writer_of(".t.csv.456.tmp"), Some(456));
        assert_eq!(writer_of("hooke-123-7.tmp"), None);
        assert_eq!(writer_of(".notes.tmp"), None);
        assert_eq!(writer_of(".hooke-x-7.tmp"), None);
    }

    #[test]
    fn a_dead_process_temporaries_are_swept_and_live_ones_kept() {
        let dir = std::env::temp_dir().join(format!("hooke-sweep-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // PID 2^22 + 1 is above Linux's largest PID, so no process has it.
        let dead = dir.join(".hooke-4194305-0.tmp");
        let legacy = dir.join(".t.csv.4194305.tmp");
        let live = dir.join(format!(".hooke-{}-999.tmp", std::process::id()));
        let mine = dir.join("notes.tmp");
        for p in [&dead, &legacy, &live, &mine] {
            std::fs::write(p, "x").unwrap();
        }
        write_atomic(&dir.join("a.csv"), b"a").unwrap();
        assert!(!dead.exists() && !legacy.exists());
        assert!(live.exists() && mine.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_long_legal_name_is_written() {
        let dir = std::env::temp_dir().join(format!("hooke-long-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let name = format!("{}.csv", "n".repeat(251));
        write_atomic(&dir.join(&name), b"a").unwrap();
        assert_eq!(std::fs::read(dir.join(&name)).unwrap(), b"a");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
