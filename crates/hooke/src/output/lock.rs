//! A folder of frames held by one run at a time: `DIR/.hooke-lock`, locked with the
//! system's advisory file lock (`flock`), which the system releases when the holder exits,
//! however it exits. The file names the holder (process id and command) for the message a
//! second run gets.

use super::named;
use crate::error::{Context, Result, bail_output};
use std::fs::{File, TryLockError};
use std::io::{Read, Write};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, Weak};

/// The lock file's name inside a held folder.
pub const LOCK_NAME: &str = ".hooke-lock";

/// A held folder; when the last handle is dropped the folder is released and the lock file
/// removed. One process takes a folder once: a second writer of the same run (frames and a
/// folder export into one folder) shares the handle.
#[derive(Clone, Debug)]
// Never read: held for its `Drop`, which releases the folder when the last handle goes.
pub struct FolderLock(#[allow(dead_code)] Arc<Held>);

#[derive(Debug)]
struct Held {
    path: PathBuf,
    file: File,
}

/// A folder's device and inode.
type FolderId = (u64, u64);

/// The folders this process holds.
static HELD: Mutex<Vec<(FolderId, Weak<Held>)>> = Mutex::new(Vec::new());

/// What this process says of itself in a lock file.
fn holder() -> String {
    let command: Vec<String> = std::env::args().collect();
    format!("process {} ({})", std::process::id(), command.join(" "))
}

impl FolderLock {
    /// Takes folder `dir` (given with option `flag`) for this run, or says which process
    /// holds it.
    pub fn take(dir: &Path, flag: &str) -> Result<Self> {
        let meta = std::fs::metadata(dir)
            .with_context(|| format!("{flag} {}: cannot read the folder", dir.display()))?;
        let key = (meta.dev(), meta.ino());
        let mut held = HELD.lock().unwrap_or_else(|e| e.into_inner());
        held.retain(|(_, w)| w.strong_count() > 0);
        if let Some(h) = held
            .iter()
            .find(|(k, _)| *k == key)
            .and_then(|(_, w)| w.upgrade())
        {
            return Ok(Self(h));
        }
        let h = Arc::new(Held::take(dir, flag)?);
        held.push((key, Arc::downgrade(&h)));
        Ok(Self(h))
    }
}

impl Held {
    /// Creates `DIR/.hooke-lock` anew (`O_EXCL | O_NOFOLLOW`: nothing planted there is
    /// opened through) and locks it. A lock file already there is opened without following
    /// a link, and only if it is a plain file of this user's with one link: locked by
    /// another run, that run is named; unlocked, it is an ended run's, and is removed and
    /// created again — never truncated, never written.
    fn take(dir: &Path, flag: &str) -> Result<Self> {
        let path = dir.join(LOCK_NAME);
        let cannot = |e: std::io::Error| {
            crate::Error::output(format!(
                "{flag} {}: cannot lock the folder: {e}",
                path.display()
            ))
        };
        // A lock file another run removes between our open and our lock is no longer the
        // folder's: try again with the new one.
        for _ in 0..8 {
            let mut file = match named::create_new(&path) {
                Ok(file) => file,
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let mut file = named::open_existing(&path, flag)?;
                    match file.try_lock() {
                        Ok(()) => {
                            // An ended run's lock: removed while we hold it, so that a run
                            // opening it meanwhile finds it gone when it gets the lock.
                            if same_file(&path, &file) {
                                std::fs::remove_file(&path).map_err(cannot)?;
                            }
                            continue;
                        }
                        Err(TryLockError::WouldBlock) => {
                            let mut said = String::new();
                            let _ = file.read_to_string(&mut said);
                            let said = said.trim();
                            bail_output!(
                                "{flag} {}: the folder is being written by another run, {}; \
                                 wait for it to end or choose another folder",
                                dir.display(),
                                if said.is_empty() {
                                    "which has not said who it is"
                                } else {
                                    said
                                }
                            );
                        }
                        Err(TryLockError::Error(e)) => return Err(cannot(e)),
                    }
                }
                Err(e) => return Err(cannot(e)),
            };
            match file.try_lock() {
                Ok(()) => {}
                // Another run took our new file for an ended run's and holds it now.
                Err(TryLockError::WouldBlock) => continue,
                Err(TryLockError::Error(e)) => return Err(cannot(e)),
            }
            if !same_file(&path, &file) {
                continue;
            }
            writeln!(file, "{}", holder())
                .with_context(|| format!("{flag} {}: cannot write {LOCK_NAME}", dir.display()))?;
            return Ok(Self { path, file });
        }
        bail_output!(
            "{flag} {}: cannot lock the folder (its lock file keeps changing)",
            dir.display()
        )
    }
}

/// Whether `path` still names the open `file` (and not a link, or another file).
fn same_file(path: &Path, file: &File) -> bool {
    std::fs::symlink_metadata(path)
        .ok()
        .zip(file.metadata().ok())
        .is_some_and(|(a, b)| (a.dev(), a.ino()) == (b.dev(), b.ino()))
}

impl Drop for Held {
    fn drop(&mut self) {
        // Removed while still locked: a run waiting on this file finds it gone and retries.
        // Only if the name is still ours: what someone put there since is left alone.
        if same_file(&self.path, &self.file) {
            let _ = std::fs::remove_file(&self.path);
        }
        let _ = self.file.unlock();
    }
}
