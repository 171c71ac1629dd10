//! Files whose names Hooke chooses inside a folder it writes (frames, a folder export's
//! files, the demo's stills, the report's page and pictures, the folder lock): nobody asked
//! for that path, so whatever stands there was put there by someone else, and Hooke must
//! not write through it. Such a name may hold nothing yet, or a plain file this user owns
//! with one link — an earlier run's output, which is replaced by a rename (a rename replaces
//! the name, never what a link leads to). A symbolic link, a hard link, a FIFO, a device, a
//! socket, a folder or another user's file is left as it is, and the run is refused with a
//! message naming the path, before anything is written.
//!
//! The files a user names on the command line (`--trajectory FILE`, `-o FILE`) are another
//! matter: a link there is the user's choice and is written through (see
//! [`mod@super::destination`]).

use crate::error::{Result, bail_output};
use std::fs::{File, Metadata, OpenOptions};
use std::os::unix::fs::{FileTypeExt, MetadataExt, OpenOptionsExt};
use std::path::Path;

/// What stands at a name Hooke writes, when it is not something Hooke may replace.
fn foreign(meta: &Metadata) -> Option<&'static str> {
    let kind = meta.file_type();
    Some(if kind.is_symlink() {
        "a symbolic link"
    } else if kind.is_dir() {
        "a folder"
    } else if kind.is_fifo() {
        "a FIFO"
    } else if kind.is_char_device() || kind.is_block_device() {
        "a device"
    } else if kind.is_socket() {
        "a socket"
    } else if !kind.is_file() {
        "not a regular file"
    } else if meta.nlink() != 1 {
        "a file with another name (a hard link)"
    } else if meta.uid() != nix::unistd::geteuid().as_raw() {
        "another user's file"
    } else {
        return None;
    })
}

/// Whether `meta` is a plain file of this user's with one link: what Hooke may replace or
/// remove under a name it chose.
pub(crate) fn is_plain(meta: &Metadata) -> bool {
    foreign(meta).is_none()
}

/// Refuses `path` (a name Hooke writes, given with option `flag`) unless nothing is there or
/// a plain file of this user's with one link: see the module's documentation.
pub fn check_named(path: &Path, flag: &str) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) => refuse_foreign(path, flag, &meta),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => bail_output!("{flag} {}: cannot look at it: {e}", path.display()),
    }
}

fn refuse_foreign(path: &Path, flag: &str, meta: &Metadata) -> Result<()> {
    if let Some(what) = foreign(meta) {
        bail_output!(
            "{flag} {}: is {what}, which hooke does not write through or replace; it writes \
             only files of its own under this name: remove it, or choose another folder",
            path.display()
        );
    }
    Ok(())
}

/// Opens the existing file at `path` for reading and writing without following a link and
/// without waiting on a FIFO, then refuses it unless it is a plain file of this user's with
/// one link (checked on the opened file, so a swap after the check cannot be written
/// through). Never truncates.
pub(crate) fn open_existing(path: &Path, flag: &str) -> Result<File> {
    check_named(path, flag)?;
    let file = OpenOptions::new()
        .read(true)
        .write(true)
        .custom_flags(nix::libc::O_NOFOLLOW | nix::libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| {
            crate::Error::output(format!("{flag} {}: cannot open it: {e}", path.display()))
        })?;
    let meta = file.metadata().map_err(|e| {
        crate::Error::output(format!("{flag} {}: cannot look at it: {e}", path.display()))
    })?;
    refuse_foreign(path, flag, &meta)?;
    Ok(file)
}

/// Creates a new file at `path`: refused when anything at all is there, a link to nowhere
/// included (`O_CREAT | O_EXCL | O_NOFOLLOW`).
pub(crate) fn create_new(path: &Path) -> std::io::Result<File> {
    OpenOptions::new()
        .read(true)
        .write(true)
        .create_new(true)
        .custom_flags(nix::libc::O_NOFOLLOW)
        .open(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_absent_names_and_plain_files_of_ours_are_taken() {
        let dir = std::env::temp_dir().join(format!("hooke-named-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let plain = dir.join("plain.png");
        std::fs::write(&plain, "x").unwrap();
        let victim = dir.join("victim.txt");
        std::fs::write(&victim, "precious").unwrap();
        let link = dir.join("link.png");
        std::os::unix::fs::symlink(&victim, &link).unwrap();
        let dangling = dir.join("dangling.png");
        std::os::unix::fs::symlink(dir.join("nowhere"), &dangling).unwrap();
        let hard = dir.join("hard.png");
        std::fs::hard_link(&victim, &hard).unwrap();
        let fifo = dir.join("fifo.png");
        nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
        let sub = dir.join("sub.png");
        std::fs::create_dir(&sub).unwrap();

        assert!(check_named(&dir.join("absent.png"), "--frames").is_ok());
        assert!(check_named(&plain, "--frames").is_ok());
        for (path, what) in [
            (&link, "symbolic link"),
            (&dangling, "symbolic link"),
            (&hard, "hard link"),
            (&fifo, "FIFO"),
            (&sub, "folder"),
        ] {
            let e = check_named(path, "--frames").unwrap_err().to_string();
            assert!(
                e.contains(what) && e.contains(&path.display().to_string()),
                "{e}"
            );
            assert!(open_existing(path, "--frames").is_err());
            assert!(create_new(path).is_err());
        }
        let e = check_named(Path::new("/dev/null"), "--out").unwrap_err();
        assert!(e.to_string().contains("a device"), "{e}");
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
