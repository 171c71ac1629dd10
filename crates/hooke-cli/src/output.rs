//! Output files that appear whole or not at all: written to a temporary file beside the
//! target, then renamed over it. Paths are checked before a run starts, so that a run never
//! simulates for minutes and then finds it cannot write its result.

use anyhow::{Context, Result, bail};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporary files being written, so that an exit forced by a repeated interrupt can still
/// remove them (see [`crate::interrupt`]).
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    // A panic while holding the lock leaves a plain list behind: still usable.
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary file still being written. For the forced exit only: the files'
/// owners are abandoned with them.
pub fn remove_pending() {
    for temp in pending().drain(..) {
        let _ = std::fs::remove_file(temp);
    }
}

/// A file being written; it replaces its target only on [`AtomicFile::commit`]. Dropped
/// without a commit, the temporary file is removed.
pub struct AtomicFile {
    target: PathBuf,
    temp: PathBuf,
    writer: Option<BufWriter<File>>,
}

/// The temporary file written for `target`: hidden, beside it, named after the process.
fn temp_path(target: &Path) -> Result<PathBuf> {
    let name = target
        .file_name()
        .with_context(|| format!("{} is not a file path", target.display()))?;
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(".{}.tmp", std::process::id()));
    Ok(target.with_file_name(temp_name))
}

/// The folder a file path lives in (`.` for a bare name).
fn folder(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

impl AtomicFile {
    /// Starts writing `target`.
    pub fn create(target: &Path) -> Result<Self> {
        check_file_path(target)?;
        let temp = temp_path(target)?;
        let file = File::create(&temp).with_context(|| {
            format!(
                "cannot write {}: cannot create a file in {}",
                target.display(),
                folder(target).display()
            )
        })?;
        pending().push(temp.clone());
        Ok(Self {
            target: target.to_path_buf(),
            temp,
            writer: Some(BufWriter::new(file)),
        })
    }

    /// The writer.
    pub fn writer(&mut self) -> &mut BufWriter<File> {
        self.writer.as_mut().expect("writer present until commit")
    }

    /// What was written so far, read from the start: for a scratch file that is copied into
    /// another and then dropped (which removes it).
    pub fn read_back(&mut self) -> Result<File> {
        self.writer()
            .flush()
            .with_context(|| format!("cannot write {}", self.target.display()))?;
        File::open(&self.temp).with_context(|| format!("cannot read back {}", self.temp.display()))
    }

    /// Flushes, syncs and renames the file into place.
    pub fn commit(mut self) -> Result<()> {
        let writer = self.writer.take().expect("commit once");
        let result = (|| {
            let file = writer
                .into_inner()
                .map_err(|e| e.into_error())
                .with_context(|| format!("cannot write {}", self.target.display()))?;
            file.sync_all()
                .with_context(|| format!("cannot write {}", self.target.display()))?;
            std::fs::rename(&self.temp, &self.target)
                .with_context(|| format!("cannot move {} into place", self.target.display()))
        })();
        if result.is_err() {
            let _ = std::fs::remove_file(&self.temp);
        }
        pending().retain(|p| p != &self.temp);
        result
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.writer.take().is_some() {
            let _ = std::fs::remove_file(&self.temp);
            pending().retain(|p| p != &self.temp);
        }
    }
}

/// Writes go to the temporary file, so an encoder can own an `AtomicFile` and hand it back
/// for the commit.
impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer().write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer().flush()
    }
}

/// Writes a whole file atomically.
pub fn write_atomic(target: &Path, bytes: &[u8]) -> Result<()> {
    let mut f = AtomicFile::create(target)?;
    f.writer()
        .write_all(bytes)
        .with_context(|| format!("cannot write {}", target.display()))?;
    f.commit()
}

/// Why a path cannot become a file, if it cannot: it ends in a separator, is an existing
/// folder, or its folder does not exist.
fn unusable_file_path(path: &Path) -> Option<String> {
    let text = path.to_string_lossy();
    if text.ends_with(std::path::MAIN_SEPARATOR) || text.ends_with('/') || path.is_dir() {
        return Some("is a folder, expected a file name".into());
    }
    let dir = folder(path);
    (!dir.is_dir()).then(|| format!("the folder {} does not exist", dir.display()))
}

fn check_file_path(path: &Path) -> Result<()> {
    match unusable_file_path(path) {
        Some(why) => bail!("cannot write {}: {why}", path.display()),
        None => Ok(()),
    }
}

/// Checks, before a run, that `path` (given with option `flag`) can take an output file of
/// one of `extensions` (lower case, without the dot; empty: any): not a folder, in an
/// existing folder that takes a new file, with a matching extension.
///
/// ```
/// # let dir = std::env::temp_dir();
/// assert!(hooke_cli::output::check_output_file(&dir, "-o", &["png"]).is_err());
/// assert!(hooke_cli::output::check_output_file(&dir.join("a.jpg"), "-o", &["png"]).is_err());
/// assert!(hooke_cli::output::check_output_file(&dir.join("a.png"), "-o", &["png"]).is_ok());
/// ```
pub fn check_output_file(path: &Path, flag: &str, extensions: &[&str]) -> Result<()> {
    if let Some(why) = unusable_file_path(path) {
        bail!("{flag} {}: {why}", path.display());
    }
    if !extensions.is_empty() {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if !extensions.contains(&ext.as_str()) {
            let list: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
            bail!(
                "{flag} {}: expected a file name ending in {} (the format written), found {}",
                path.display(),
                list.join(" or "),
                if ext.is_empty() {
                    "no extension".to_string()
                } else {
                    format!(".{ext}")
                }
            );
        }
    }
    // A probe: the folder takes a new file now, not only in principle.
    let probe = temp_path(path)?;
    File::create(&probe).with_context(|| {
        format!(
            "{flag} {}: cannot create a file in {}",
            path.display(),
            folder(path).display()
        )
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Checks, before a run, that `dir` (given with option `flag`) can be an output folder: it
/// is one, or nothing is there yet (it is created when the run starts).
pub fn check_output_folder(dir: &Path, flag: &str) -> Result<()> {
    // `file/` does not exist as a path (the file is no folder), but `file` does.
    let text = dir.to_string_lossy();
    let bare = Path::new(text.trim_end_matches(['/', std::path::MAIN_SEPARATOR]));
    if (dir.exists() && !dir.is_dir()) || (bare.exists() && !bare.is_dir()) {
        bail!("{flag} {}: is a file, expected a folder", dir.display());
    }
    Ok(())
}

/// Prepares folder `dir` (given with option `flag`) for numbered frames `frame-NNNNN.ext`:
/// creates it if missing, refuses a file, and removes the frames an earlier run left there,
/// so that the folder holds exactly this run's frames. Returns how many were removed.
pub fn prepare_frame_folder(dir: &Path, flag: &str, ext: &str) -> Result<usize> {
    check_output_folder(dir, flag)?;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{flag} {}: cannot create the folder", dir.display()))?;
    let mut removed = 0;
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("{flag} {}: cannot read", dir.display()))?;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if is_frame_name(&name, ext) {
            std::fs::remove_file(entry.path()).with_context(|| {
                format!(
                    "{flag}: cannot remove the stale frame {}",
                    entry.path().display()
                )
            })?;
            removed += 1;
        }
    }
    // Probe that frames can be written.
    check_output_file(&dir.join(frame_name(0, ext)), flag, &[ext])?;
    Ok(removed)
}

/// `frame-00042.ext`.
pub fn frame_name(frame: u64, ext: &str) -> String {
    format!("frame-{frame:05}.{ext}")
}

fn is_frame_name(name: &str, ext: &str) -> bool {
    name.strip_prefix("frame-")
        .and_then(|rest| rest.strip_suffix(ext))
        .and_then(|digits| digits.strip_suffix('.'))
        .is_some_and(|d| d.len() >= 5 && d.bytes().all(|b| b.is_ascii_digit()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_names_are_recognised_exactly() {
        assert!(is_frame_name("frame-00000.png", "png"));
        assert!(is_frame_name("frame-123456.png", "png"));
        assert!(!is_frame_name("frame-0001.png", "png"));
        assert!(!is_frame_name("frame-00000.obj", "png"));
        assert!(!is_frame_name("my-frame-00000.png", "png"));
        assert_eq!(frame_name(7, "obj"), "frame-00007.obj");
    }

    #[test]
    fn unusable_paths_are_refused_before_anything_is_written() {
        let dir = std::env::temp_dir().join(format!("hooke-output-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let slash = format!("{}/", dir.join("out").display());
        for (path, expect) in [
            (dir.clone(), "is a folder"),
            (PathBuf::from(&slash), "is a folder"),
            (dir.join("no/such/a.csv"), "does not exist"),
        ] {
            let e = check_output_file(&path, "--trajectory", &[]).unwrap_err();
            assert!(format!("{e:#}").contains(expect), "{path:?}: {e:#}");
            assert!(AtomicFile::create(&path).is_err());
        }
        let e = check_output_file(&dir.join("x.jpg"), "-o", &["png"]).unwrap_err();
        assert!(format!("{e:#}").contains("ending in .png"), "{e:#}");
        assert!(check_output_file(&dir.join("x.PNG"), "-o", &["png"]).is_ok());
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().collect();
        assert!(names.is_empty(), "left behind: {names:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
