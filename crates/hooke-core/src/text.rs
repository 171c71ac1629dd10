//! Reading a user's text file (a scene, a mesh, a material, a `.w` world) as they have it
//! (and a binary input, a vertex cache, by the same rules):
//! a regular file only, of a size a text input can have, with a UTF-8 byte-order mark (as
//! Windows editors write) skipped and a byte that is not UTF-8 named by its line. Every
//! input reader of the workspace goes through [`read_text`], so that a device, a pipe or a
//! folder named as an input is refused before anything is read (`/dev/zero` would be read
//! until memory ran out; a pipe with no writer would wait for ever).

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// The largest text input read, bytes (1 GiB): an OBJ of some ten million vertices. What
/// the machine can hold is the caller's to check; this bounds what any reader allocates.
const MOST_TEXT_BYTES: u64 = 1 << 30;

/// The UTF-8 byte-order mark.
const BOM: char = '\u{feff}';

/// What a path that is not a regular file is, in words.
fn kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

/// The text of the regular file at `path`, without a leading byte-order mark.
///
/// Refused before anything is read, as an error of kind `InvalidInput` saying why: a path
/// that is a folder, a device, a pipe or a socket, and a file over 1 GiB. A
/// byte that is not UTF-8 is refused as `InvalidData`, naming its line and column.
///
/// ```
/// let e = hooke_core::text::read_text(std::path::Path::new("/dev/null")).unwrap_err();
/// assert!(e.to_string().contains("a character device"), "{e}");
/// ```
pub fn read_text(path: &Path) -> std::io::Result<String> {
    let bytes = read_regular(path, "a text file")?;
    match String::from_utf8(bytes) {
        Ok(mut text) => {
            if text.starts_with(BOM) {
                text.drain(..BOM.len_utf8());
            }
            Ok(text)
        }
        Err(e) => {
            let good = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let line = good.iter().filter(|&&b| b == b'\n').count() + 1;
            let column =
                good.len() - good.iter().rposition(|&b| b == b'\n').map_or(0, |k| k + 1) + 1;
            let byte = e.as_bytes()[good.len()];
            Err(Error::new(
                ErrorKind::InvalidData,
                format!(
                    "line {line}, column {column}: byte {byte:#04x} is not UTF-8 text (save the \
                     file as UTF-8)"
                ),
            ))
        }
    }
}

/// The bytes of the regular file at `path` (a binary input: a vertex cache), refused as
/// [`read_text`] refuses a folder, a device, a pipe or a file over 1 GiB, before anything is
/// read.
///
/// ```
/// let e = hooke_core::text::read_bytes(std::path::Path::new("/dev/zero")).unwrap_err();
/// assert!(e.to_string().contains("a character device"), "{e}");
/// ```
pub fn read_bytes(path: &Path) -> std::io::Result<Vec<u8>> {
    read_regular(path, "a file")
}

/// The bytes of the regular file at `path`, at most [`MOST_TEXT_BYTES`]; `expected` names
/// what it should have been in the error for anything else.
fn read_regular(path: &Path, expected: &str) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{}, not a regular file (expected {expected})", kind(&meta)),
        ));
    }
    if meta.len() > MOST_TEXT_BYTES {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // The file may have grown since: never read past the bound.
    std::fs::File::open(path)?
        .take(MOST_TEXT_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MOST_TEXT_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

fn too_large(len: u64) -> Error {
    Error::new(
        ErrorKind::InvalidInput,
        format!(
            "{len} bytes is more than the {} MiB an input may have",
            MOST_TEXT_BYTES >> 20
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let path = std::env::temp_dir().join(format!("hooke-text-{}-{name}", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn a_byte_order_mark_is_skipped_and_crlf_kept_for_the_parsers() {
        let path = file("bom", b"\xef\xbb\xbfv 0 0 0\r\nv 1 0 0\r\n");
        assert_eq!(read_text(&path).unwrap(), "v 0 0 0\r\nv 1 0 0\r\n");
        std::fs::remove_file(path).unwrap();
    }

    #[test]
    fn a_byte_that_is_not_utf8_is_named_by_its_line_and_column() {
        let path = file("latin1", b"v 0 0 0\nv 1 \xe9 0\n");
        let e = read_text(&path).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::InvalidData);
        assert!(
            e.to_string().starts_with("line 2, column 5: byte 0xe9"),
            "{e}"
        );
        std::fs::remove_file(path).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn devices_folders_and_pipes_are_refused_before_they_are_read() {
        for (path, what) in [
            ("/dev/zero", "a character device"),
            ("/dev/urandom", "a character device"),
            ("/tmp", "a folder"),
        ] {
            let e = read_text(Path::new(path)).unwrap_err();
            assert_eq!(e.kind(), ErrorKind::InvalidInput);
            assert!(e.to_string().contains(what), "{path}: {e}");
        }
        // A pipe with no writer: opening it would block for ever.
        let fifo = std::env::temp_dir().join(format!("hooke-text-{}-fifo", std::process::id()));
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let e = read_text(&fifo).unwrap_err();
            assert!(e.to_string().contains("named pipe"), "{e}");
            std::fs::remove_file(&fifo).unwrap();
        }
    }
}
