//! Outputs: files that appear whole or not at all ([`mod@file`]), streams written straight
//! through ([`mod@destination`]), outputs checked against inputs and each other before a run
//! ([`claims`]), folders of frames held by one run at a time ([`lock`]). Paths are checked
//! before a run starts, so that a run never simulates for minutes and then finds it cannot
//! write its result.

pub mod claims;
pub mod destination;
pub mod file;
pub mod lock;
pub(crate) mod marker;
pub mod named;

pub use file::{OutputFile, remove_pending, write_atomic, write_named};
pub use marker::FRAMES_MARKER;
pub(crate) use marker::record_frame;
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

/// Creates folder `dir` (given with option `flag`) and any missing folders above it; when
/// that fails because something on the way is not a folder (a file, a link to nothing),
/// says which.
pub fn create_folder(dir: &Path, flag: &str) -> Result<()> {
    let Err(e) = std::fs::create_dir_all(dir) else {
        return Ok(());
    };
    for above in dir.ancestors().filter(|a| !a.as_os_str().is_empty()) {
        let Ok(meta) = std::fs::symlink_metadata(above) else {
            continue;
        };
        if meta.file_type().is_symlink() && std::fs::metadata(above).is_err() {
            let target = std::fs::read_link(above).unwrap_or_default();
            bail_output!(
                "{flag} {}: cannot create the folder: {} is a symbolic link to nothing ({}); \
                 point it at a folder, or choose another path",
                dir.display(),
                above.display(),
                target.display()
            );
        }
        if !meta.is_dir() && !meta.file_type().is_symlink() {
            bail_output!(
                "{flag} {}: cannot create the folder: {} is a file, not a folder",
                dir.display(),
                above.display()
            );
        }
    }
    Err(crate::Error::from(e).context(format!(
        "{flag} {}: cannot create the folder",
        dir.display()
    )))
}

/// Prepares folder `dir` (given with option `flag`) for numbered frames `frame-NNNNN.ext`:
/// creates it if missing, refuses a file, takes it for this run (refused while another run
/// holds it), and removes the frames an earlier run left there, so that the folder holds
/// exactly this run's frames. Returns the folder's lock, held while the frames are written,
/// and how many frames were removed.
///
/// Only frames that the folder's marker ([`FRAMES_MARKER`], `marker.rs`) records as written
/// by Hooke, and that are unchanged since, are removed. A file named like a frame of this
/// run's kind that Hooke did not write (a video's frames extracted as `frame-%05d.png`, a
/// frame a person edited) would be replaced by this run's frame: the run is refused, naming
/// it, and the folder is left as it was. One of another kind stays, and the run says so. A
/// file under the marker's name that Hooke did not write is never replaced: the run is
/// refused.
pub fn prepare_frame_folder(dir: &Path, flag: &str, ext: &str) -> Result<(FolderLock, usize)> {
    check_output_folder(dir, flag)?;
    create_folder(dir, flag)?;
    let lock = FolderLock::take(dir, flag)?;
    let record = match marker::read(dir, flag)? {
        marker::Marker::Hookes(record) => record,
        marker::Marker::Absent => marker::Record::default(),
        marker::Marker::Foreign(first) => bail_output!(
            "{flag} {}: its {FRAMES_MARKER} file was not written by hooke (it begins {first:?}), \
             so nothing in this folder is taken for hooke's; remove that file, or choose a new \
             or empty folder",
            dir.display()
        ),
    };
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("{flag} {}: cannot read", dir.display()))?;
    // Every stale frame is looked at before any is removed: a link, a second name or a
    // device under a frame's name refuses the run and leaves the folder as it was.
    let mut stale = Vec::new();
    let mut foreign = Vec::new();
    let mut kept = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if !is_any_frame_name(&name) {
            continue;
        }
        let ours = std::fs::symlink_metadata(entry.path())
            .is_ok_and(|meta| named::is_plain(&meta) && record.wrote(&name, &meta));
        if ours && is_frame_name(&name, ext) {
            named::check_named(&entry.path(), flag)?;
            stale.push(entry.path());
        } else if is_frame_name(&name, ext) {
            foreign.push(name);
        } else if !ours {
            kept.push(name);
        }
    }
    if !foreign.is_empty() {
        let (count, first) = some_files(&mut foreign);
        bail_output!(
            "{flag} {}: holds {count} named like this run's frames ({first}) that hooke did not \
             write (or that changed since it wrote them: the folder's {FRAMES_MARKER} does not \
             record them), so they are not hooke's to replace; choose a new or empty folder, or \
             move them away",
            dir.display(),
        );
    }
    if !kept.is_empty() {
        let (count, first) = some_files(&mut kept);
        eprintln!(
            "{flag} {}: kept {count} named like frames that hooke did not write ({first})",
            dir.display(),
        );
    }
    // The marker keeps the records of the frames of other kinds still there (a folder shared
    // by --frames and --export); this run's kind is recorded again as it is written.
    let text = record.text(|name| {
        !is_frame_name(name, ext) && std::fs::symlink_metadata(dir.join(name)).is_ok()
    });
    write_named(&dir.join(FRAMES_MARKER), flag, text.as_bytes())?;
    for path in &stale {
        std::fs::remove_file(path)
            .with_context(|| format!("{flag}: cannot remove the stale frame {}", path.display()))?;
    }
    let removed = stale.len();
    // Probe that frames can be written.
    check_output_file(&dir.join(frame_name(0, ext)), flag, &[ext])?;
    Ok((lock, removed))
}

/// `names` sorted and said in short: `a file` or `N files`, and the first name (with `, …`
/// when there are more).
fn some_files(names: &mut [String]) -> (String, String) {
    names.sort();
    let count = match names.len() {
        1 => "a file".to_string(),
        n => format!("{n} files"),
    };
    let more = if names.len() > 1 { ", …" } else { "" };
    (count, format!("{}{more}", names[0]))
}

/// `frame-00042.ext`.
pub fn frame_name(frame: u64, ext: &str) -> String {
    format!("frame-{frame:05}.{ext}")
}

/// Whether `name` is `frame-` followed by five or more digits, a dot and any extension.
fn is_any_frame_name(name: &str) -> bool {
    name.rsplit_once('.')
        .is_some_and(|(_, ext)| !ext.is_empty() && is_frame_name(name, ext))
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
        assert!(is_any_frame_name("frame-00500.png"));
        assert!(is_any_frame_name("frame-00500.jpg"));
        assert!(!is_any_frame_name("frame-00500."));
        assert!(!is_any_frame_name("frames.txt"));
    }

    #[test]
    fn a_users_file_named_like_a_frame_is_never_removed() {
        let dir = std::env::temp_dir().join(format!("hooke-users-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mine = dir.join("frame-00500.png");
        std::fs::write(&mine, b"mine").unwrap();
        let e = prepare_frame_folder(&dir, "--frames", "png").unwrap_err();
        assert!(format!("{e:#}").contains("frame-00500.png"), "{e:#}");
        assert!(format!("{e:#}").contains(FRAMES_MARKER), "{e:#}");
        assert!(!dir.join(FRAMES_MARKER).exists());
        // A frame of another format is a user's file too: this run writes none of its
        // names, so it is kept (and said) while the run takes the folder.
        let (lock, removed) = prepare_frame_folder(&dir, "--export", "ply").unwrap();
        assert_eq!(removed, 0);
        assert_eq!(std::fs::read(&mine).unwrap(), b"mine");
        drop(lock);
        // A folder hooke marked holds hooke's frames: those it recorded are replaced by the
        // next run.
        std::fs::remove_file(&mine).unwrap();
        std::fs::write(dir.join("notes.txt"), b"kept").unwrap();
        let (lock, removed) = prepare_frame_folder(&dir, "--frames", "png").unwrap();
        assert_eq!(removed, 0);
        assert!(dir.join(FRAMES_MARKER).exists());
        let written = dir.join("frame-00000.png");
        write_named(&written, "--frames", b"a frame").unwrap();
        record_frame(&written, "--frames").unwrap();
        drop(lock);
        let (lock, removed) = prepare_frame_folder(&dir, "--frames", "png").unwrap();
        assert_eq!(removed, 1);
        // A file a person put there under a frame's name is not hooke's: the run is refused
        // and the file stays, though the folder is marked.
        std::fs::write(dir.join("frame-00001.png"), b"mine").unwrap();
        drop(lock);
        let e = prepare_frame_folder(&dir, "--frames", "png").unwrap_err();
        assert!(format!("{e:#}").contains("frame-00001.png"), "{e:#}");
        assert_eq!(std::fs::read(dir.join("frame-00001.png")).unwrap(), b"mine");
        // Nor is a recorded frame a person changed since.
        std::fs::remove_file(dir.join("frame-00001.png")).unwrap();
        let (lock, _) = prepare_frame_folder(&dir, "--frames", "png").unwrap();
        write_named(&written, "--frames", b"a frame").unwrap();
        record_frame(&written, "--frames").unwrap();
        std::fs::write(&written, b"edited by hand").unwrap();
        drop(lock);
        assert!(prepare_frame_folder(&dir, "--frames", "png").is_err());
        assert_eq!(std::fs::read(&written).unwrap(), b"edited by hand");
        std::fs::remove_file(&written).unwrap();
        // A marker hooke did not write (empty, planted) takes nothing.
        std::fs::write(dir.join(FRAMES_MARKER), b"").unwrap();
        std::fs::write(dir.join("frame-00002.ply"), b"mine").unwrap();
        let e = prepare_frame_folder(&dir, "--frames", "png").unwrap_err();
        assert!(format!("{e:#}").contains(FRAMES_MARKER), "{e:#}");
        assert_eq!(std::fs::read(dir.join("frame-00002.ply")).unwrap(), b"mine");
        std::fs::write(dir.join(FRAMES_MARKER), marker::HEADER).unwrap();
        let (lock, removed) = prepare_frame_folder(&dir, "--frames", "png").unwrap();
        assert_eq!(removed, 0);
        assert_eq!(std::fs::read(dir.join("frame-00002.ply")).unwrap(), b"mine");
        assert_eq!(std::fs::read(dir.join("notes.txt")).unwrap(), b"kept");
        drop(lock);
        std::fs::remove_dir_all(&dir).unwrap();
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
