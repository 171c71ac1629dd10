//! Outputs: files that appear whole or not at all ([`mod@file`]), streams written straight
//! through ([`mod@destination`]), outputs checked against inputs and each other before a run
//! ([`claims`]), folders of frames held by one run at a time ([`lock`]). Paths are checked
//! before a run starts, so that a run never simulates for minutes and then finds it cannot
//! write its result.

pub mod claims;
pub mod destination;
pub mod file;
pub mod lock;
pub mod named;

pub use file::{OutputFile, remove_pending, write_atomic, write_named};
pub use named::check_named;

use crate::error::{Context, Result, bail_output};
use destination::{Destination, destination};
use lock::FolderLock;
use std::path::Path;

/// Checks, before a run, that `path` (given with option `flag`) can take an output file of
/// one of `extensions` (lower case, without the dot; empty: any): `-` (standard output), a
/// character device or a FIFO, which are written straight through whatever their names;
/// or a file name, not a folder, in an existing folder that takes a new file, with a
/// matching extension. Returns what the path is.
///
/// ```
/// # let dir = std::env::temp_dir();
/// assert!(hooke::output::check_output_file(&dir, "-o", &["png"]).is_err());
/// assert!(hooke::output::check_output_file(&dir.join("a.jpg"), "-o", &["png"]).is_err());
/// assert!(hooke::output::check_output_file(&dir.join("a.png"), "-o", &["png"]).is_ok());
/// assert!(hooke::output::check_output_file("/dev/null".as_ref(), "-o", &["png"]).is_ok());
/// ```
pub fn check_output_file(path: &Path, flag: &str, extensions: &[&str]) -> Result<Destination> {
    let found = destination(path, flag)?;
    let Destination::File { target } = &found else {
        return Ok(found);
    };
    if !extensions.is_empty() {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if !extensions.contains(&ext.as_str()) {
            let list: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
            bail_output!(
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
    let dir = destination::folder(target);
    let probe = file::temp_in(dir);
    named::create_new(&probe).with_context(|| {
        format!(
            "{flag} {}: cannot create a file in {}",
            path.display(),
            dir.display()
        )
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(found)
}

/// Checks, before a run, that `dir` (given with option `flag`) can be an output folder: it
/// is one, or nothing is there yet (it is created when the run starts).
pub fn check_output_folder(dir: &Path, flag: &str) -> Result<()> {
    use std::os::unix::fs::FileTypeExt;
    if dir.as_os_str() == "-" {
        bail_output!("{flag} -: expected a folder; standard output cannot hold a folder");
    }
    // `file/` does not exist as a path (the file is no folder), but `file` does.
    let text = dir.to_string_lossy();
    let bare = Path::new(text.trim_end_matches(['/', std::path::MAIN_SEPARATOR]));
    for path in [dir, bare] {
        match std::fs::metadata(path) {
            Ok(meta) if meta.is_dir() => {}
            Ok(meta) => {
                let kind = meta.file_type();
                let what = if kind.is_char_device() || kind.is_block_device() {
                    "a device"
                } else if kind.is_fifo() {
                    "a FIFO"
                } else if kind.is_socket() {
                    "a socket"
                } else {
                    "a file"
                };
                bail_output!("{flag} {}: is {what}, expected a folder", dir.display());
            }
            Err(_) if std::fs::symlink_metadata(path).is_ok() => {
                bail_output!(
                    "{flag} {}: is a symbolic link to nothing, expected a folder",
                    dir.display()
                );
            }
            Err(_) => {}
        }
    }
    Ok(())
}

/// Prepares folder `dir` (given with option `flag`) for numbered frames `frame-NNNNN.ext`:
/// creates it if missing, refuses a file, takes it for this run (refused while another run
/// holds it), and removes the frames an earlier run left there, so that the folder holds
/// exactly this run's frames. Returns the folder's lock, held while the frames are written,
/// and how many frames were removed.
pub fn prepare_frame_folder(dir: &Path, flag: &str, ext: &str) -> Result<(FolderLock, usize)> {
    check_output_folder(dir, flag)?;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{flag} {}: cannot create the folder", dir.display()))?;
    let lock = FolderLock::take(dir, flag)?;
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("{flag} {}: cannot read", dir.display()))?;
    // Every stale frame is looked at before any is removed: a link, a second name or a
    // device under a frame's name refuses the run and leaves the folder as it was.
    let mut stale = Vec::new();
    for entry in entries.flatten() {
        if is_frame_name(&entry.file_name().to_string_lossy(), ext) {
            named::check_named(&entry.path(), flag)?;
            stale.push(entry.path());
        }
    }
    for path in &stale {
        std::fs::remove_file(path)
            .with_context(|| format!("{flag}: cannot remove the stale frame {}", path.display()))?;
    }
    let removed = stale.len();
    // Probe that frames can be written.
    check_output_file(&dir.join(frame_name(0, ext)), flag, &[ext])?;
    Ok((lock, removed))
}

/// `frame-00042.ext`.
pub fn frame_name(frame: u64, ext: &str) -> String {
    format!("frame-{frame:05}.{ext}")
}

pub(crate) fn is_frame_name(name: &str, ext: &str) -> bool {
    name.strip_prefix("frame-")
        .and_then(|rest| rest.strip_suffix(ext))
        .and_then(|digits| digits.strip_suffix('.'))
        .is_some_and(|d| d.len() >= 5 && d.bytes().all(|b| b.is_ascii_digit()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

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
    fn streams_are_written_through_and_never_replaced() {
        use std::io::Write;
        let null = Path::new("/dev/null");
        let before = std::fs::metadata(null).unwrap();
        check_output_file(null, "--trajectory", &["csv"]).unwrap();
        let mut f = OutputFile::create(null).unwrap();
        f.writer().write_all(b"frame\n").unwrap();
        f.commit().unwrap();
        write_atomic(null, b"again").unwrap();
        let after = std::fs::metadata(null).unwrap();
        use std::os::unix::fs::{FileTypeExt, MetadataExt};
        assert!(after.file_type().is_char_device());
        assert_eq!((before.ino(), before.rdev()), (after.ino(), after.rdev()));
        // A full device says so at the write, not with a replaced device.
        if Path::new("/dev/full").exists() {
            let e = write_atomic(Path::new("/dev/full"), &[0; 1 << 16]).unwrap_err();
            assert!(format!("{e:#}").contains("/dev/full"), "{e:#}");
            assert!(
                std::fs::metadata("/dev/full")
                    .unwrap()
                    .file_type()
                    .is_char_device()
            );
        }
    }

    #[test]
    fn a_frame_folder_is_held_by_one_run() {
        let dir = std::env::temp_dir().join(format!("hooke-held-{}", std::process::id()));
        let (lock, _) = prepare_frame_folder(&dir, "--frames", "png").unwrap();
        // The same process, another writer: shares the folder.
        let (again, _) = prepare_frame_folder(&dir, "--export", "ply").unwrap();
        assert!(dir.join(lock::LOCK_NAME).exists());
        drop((lock, again));
        assert!(!dir.join(lock::LOCK_NAME).exists());
        std::fs::remove_dir_all(&dir).unwrap();
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
            assert!(OutputFile::create(&path).is_err());
        }
        let e = check_output_file(&dir.join("x.jpg"), "-o", &["png"]).unwrap_err();
        assert!(format!("{e:#}").contains("ending in .png"), "{e:#}");
        assert!(check_output_file(&dir.join("x.PNG"), "-o", &["png"]).is_ok());
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().collect();
        assert!(names.is_empty(), "left behind: {names:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
