//! The `.hooke-frames` marker: the record of the frames Hooke wrote into a folder, so that a
//! later run removes exactly those and nothing a person put there.
//!
//! The marker's first line says what it is ([`HEADER`]); each further line records one
//! frame Hooke wrote, as `NAME SIZE INODE MTIME_NS`, appended as the frame is committed. A
//! file named like a frame counts as Hooke's only while it is recorded and its size, inode
//! and modification time are still those recorded: a frame a person replaced, or a file a
//! person put there under a frame's name, is not Hooke's. A marker whose first line is
//! anything else (empty, planted, written by an older Hooke that kept no record) records
//! nothing.

use super::named;
use crate::error::{Context, Result};
use std::collections::BTreeMap;
use std::io::Write;
use std::os::unix::fs::MetadataExt;
use std::path::Path;

/// The marker's file name.
pub const FRAMES_MARKER: &str = ".hooke-frames";

/// The marker's first line.
pub(crate) const HEADER: &str = "hooke frames 1: this folder holds frames written by hooke \
(frame-NNNNN.png, .ply, .obj); each line below records one, as name, size, inode and \
modification time, and a later run replaces only the frames recorded here";

/// What identifies a file Hooke wrote: its size, inode and modification time (ns).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Stamp {
    size: u64,
    ino: u64,
    mtime_ns: i128,
}

impl Stamp {
    fn of(meta: &std::fs::Metadata) -> Self {
        Self {
            size: meta.len(),
            ino: meta.ino(),
            mtime_ns: i128::from(meta.mtime()) * 1_000_000_000 + i128::from(meta.mtime_nsec()),
        }
    }
}

/// A marker as read: whether it is Hooke's, and the frames it records.
#[derive(Debug, Default)]
pub(crate) struct Record {
    frames: BTreeMap<String, Stamp>,
}

/// What a folder's marker says.
#[derive(Debug)]
pub(crate) enum Marker {
    /// No marker.
    Absent,
    /// A marker Hooke wrote, with what it records.
    Hookes(Record),
    /// A file under the marker's name that Hooke did not write (empty, planted, or of an
    /// older Hooke, which kept no record): its first line.
    Foreign(String),
}

/// Reads the marker of folder `dir` (refusing a link, FIFO or device under its name).
pub(crate) fn read(dir: &Path, flag: &str) -> Result<Marker> {
    let path = dir.join(FRAMES_MARKER);
    named::check_named(&path, flag)?;
    let text = match std::fs::read(&path) {
        Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Marker::Absent),
        Err(e) => {
            return Err(crate::Error::from(e)
                .context(format!("{flag} {}: cannot read the marker", path.display())));
        }
    };
    Ok(parse(&text))
}

/// The marker's text read: a record when its first line is [`HEADER`]; lines that do not
/// parse (a line torn by a crash while it was appended) record nothing.
fn parse(text: &str) -> Marker {
    let mut lines = text.lines();
    let first = lines.next().unwrap_or("");
    if first != HEADER {
        return Marker::Foreign(first.chars().take(60).collect());
    }
    let mut record = Record::default();
    for line in lines {
        let fields: Vec<&str> = line.split(' ').collect();
        let [name, size, ino, mtime] = fields[..] else {
            continue;
        };
        let (Ok(size), Ok(ino), Ok(mtime_ns)) = (size.parse(), ino.parse(), mtime.parse()) else {
            continue;
        };
        record.frames.insert(
            name.to_string(),
            Stamp {
                size,
                ino,
                mtime_ns,
            },
        );
    }
    Marker::Hookes(record)
}

impl Record {
    /// Whether the file `name` in the folder, with metadata `meta`, is a frame this record
    /// holds, unchanged since it was written.
    pub(crate) fn wrote(&self, name: &str, meta: &std::fs::Metadata) -> bool {
        self.frames.get(name) == Some(&Stamp::of(meta))
    }

    /// The marker's text holding the frames of this record that `keep` keeps.
    pub(crate) fn text(&self, keep: impl Fn(&str) -> bool) -> String {
        let mut text = format!("{HEADER}\n");
        for (name, s) in self.frames.iter().filter(|(n, _)| keep(n)) {
            text.push_str(&line(name, s));
        }
        text
    }
}

fn line(name: &str, s: &Stamp) -> String {
    format!("{name} {} {} {}\n", s.size, s.ino, s.mtime_ns)
}

/// Records in the marker of the folder holding `path` that Hooke has just written the frame
/// at `path` (given with option `flag`): a line appended, through no link.
pub(crate) fn record_frame(path: &Path, flag: &str) -> Result<()> {
    let (Some(dir), Some(name)) = (path.parent(), path.file_name()) else {
        return Ok(());
    };
    let meta = std::fs::symlink_metadata(path).with_context(|| {
        format!(
            "{flag} {}: cannot look at the frame written",
            path.display()
        )
    })?;
    let marker = dir.join(FRAMES_MARKER);
    let mut file = named::open_existing(&marker, flag)?;
    use std::io::Seek;
    file.seek(std::io::SeekFrom::End(0))
        .and_then(|_| file.write_all(line(&name.to_string_lossy(), &Stamp::of(&meta)).as_bytes()))
        .with_context(|| format!("{flag} {}: cannot record the frame", marker.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_marker_with_the_header_records_frames() {
        assert!(matches!(parse(""), Marker::Foreign(_)));
        assert!(matches!(
            parse("anything\nframe-00000.png 1 2 3\n"),
            Marker::Foreign(_)
        ));
        let legacy = "hooke: this folder holds frames written by hooke (frame-NNNNN.png, .ply, \
                      .obj); a later run into it replaces them\n";
        assert!(matches!(parse(legacy), Marker::Foreign(_)));
        let Marker::Hookes(r) = parse(&format!(
            "{HEADER}\nframe-00000.png 10 20 30\nframe-00001.png 1 torn\n"
        )) else {
            panic!("the header was not recognised");
        };
        assert_eq!(r.frames.len(), 1);
        assert_eq!(
            r.text(|n| n.ends_with(".png")),
            format!("{HEADER}\nframe-00000.png 10 20 30\n")
        );
        assert_eq!(r.text(|_| false), format!("{HEADER}\n"));
    }
}
