//! Before a run: no output may replace an input or another output. Files are compared by
//! identity (device and inode for what exists, the resolved path for what does not yet),
//! not by spelling, so `./s.toml`, a symbolic link to it and a hard link all count as the
//! scene file. A folder of numbered frames claims the frame names in it: an input or an
//! output named like one of its frames would be removed or rewritten by the run.

use super::destination::{Destination, destination};
use crate::error::{Result, bail_output};
use std::os::unix::fs::MetadataExt;
use std::path::{Component, Path, PathBuf};

/// Where a path leads, as far as it exists.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Id {
    /// Standard output.
    Stdout,
    /// An existing file, folder or device.
    Node(u64, u64),
    /// Nothing yet: the absolute path it would have, links in its existing part resolved.
    New(PathBuf),
}

/// `path` made absolute, with `.` and `..` folded and the longest existing prefix resolved.
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in absolute.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => {
                out.push(other);
                if let Ok(p) = out.canonicalize() {
                    out = p;
                }
            }
        }
    }
    out
}

fn id(path: &Path) -> Id {
    if path.as_os_str() == "-" {
        return Id::Stdout;
    }
    match std::fs::metadata(path) {
        Ok(m) => Id::Node(m.dev(), m.ino()),
        Err(_) => Id::New(resolved(path)),
    }
}

/// The identity of the folder `path` lies in.
fn folder_id(path: &Path) -> Id {
    let full = resolved(path);
    id(full.parent().unwrap_or(Path::new("/")))
}

/// What an output writes.
#[derive(Clone, Debug)]
enum Kind {
    /// One file.
    File,
    /// `frame-NNNNN.EXT` files in a folder.
    Frames(String),
}

#[derive(Clone, Debug)]
struct Output {
    flag: String,
    path: PathBuf,
    kind: Kind,
}

/// The inputs and outputs of one command, to be checked against each other.
#[derive(Default, Debug)]
pub struct Claims {
    inputs: Vec<(String, PathBuf)>,
    outputs: Vec<Output>,
}

/// Whether `path` is the null device, which any number of outputs may share.
fn is_null(path: &Path) -> bool {
    matches!(
        (std::fs::metadata(path), std::fs::metadata("/dev/null")),
        (Ok(a), Ok(b)) if a.rdev() == b.rdev() && a.dev() == b.dev() && a.ino() == b.ino()
    )
}

impl Claims {
    /// Claims starting from the files a command reads, each with what to call it in a
    /// message (as [`crate::source::Source::inputs`] gives them).
    pub fn with_inputs(inputs: impl IntoIterator<Item = (String, PathBuf)>) -> Self {
        Self {
            inputs: inputs.into_iter().collect(),
            outputs: Vec::new(),
        }
    }

    /// A file the command reads: `what` names it in messages (`the scene file`).
    pub fn input(&mut self, what: impl Into<String>, path: &Path) {
        self.inputs.push((what.into(), path.to_path_buf()));
    }

    /// A file the command writes, given with option `flag`.
    pub fn file(&mut self, flag: impl Into<String>, path: &Path) {
        self.outputs.push(Output {
            flag: flag.into(),
            path: path.to_path_buf(),
            kind: Kind::File,
        });
    }

    /// A folder the command fills with `frame-NNNNN.ext`, given with option `flag`.
    pub fn frames(&mut self, flag: impl Into<String>, dir: &Path, ext: &str) {
        self.outputs.push(Output {
            flag: flag.into(),
            path: dir.to_path_buf(),
            kind: Kind::Frames(ext.to_string()),
        });
    }

    /// Refuses, with what to change, an output that is an input, two outputs that are one
    /// file, and a file (read or written) named like a frame in a folder of frames.
    ///
    /// ```
    /// use hooke::output::claims::Claims;
    /// let dir = std::env::temp_dir();
    /// let scene = dir.join(format!("claims-doc-{}.toml", std::process::id()));
    /// std::fs::write(&scene, "").unwrap();
    /// let mut claims = Claims::default();
    /// claims.input("the scene file", &scene);
    /// claims.file("--trajectory", &dir.join(".").join(scene.file_name().unwrap()));
    /// assert!(claims.check().is_err());
    /// std::fs::remove_file(&scene).unwrap();
    /// ```
    pub fn check(&self) -> Result<()> {
        let inputs: Vec<(&str, &Path, Id)> = self
            .inputs
            .iter()
            .map(|(what, p)| (what.as_str(), p.as_path(), id(p)))
            .collect();
        let ids: Vec<Id> = self.outputs.iter().map(|o| id(&o.path)).collect();
        for (k, out) in self.outputs.iter().enumerate() {
            let shown = out.path.display();
            match &out.kind {
                Kind::File => {
                    let me = &ids[k];
                    for (what, path, input) in &inputs {
                        if input == me {
                            bail_output!(
                                "{} {shown}: is {what} {}, which this run reads; refusing to \
                                 overwrite it, choose another name",
                                out.flag,
                                path.display()
                            );
                        }
                    }
                    for (other, other_id) in self.outputs[..k].iter().zip(&ids) {
                        if matches!(other.kind, Kind::File) && other_id == me && !is_null(&out.path)
                        {
                            if *me == Id::Stdout {
                                bail_output!(
                                    "{} and {} both write to standard output: give one of them \
                                     a file",
                                    other.flag,
                                    out.flag
                                );
                            }
                            bail_output!(
                                "{} {shown} and {} {} are the same file: each output needs its \
                                 own",
                                out.flag,
                                other.flag,
                                other.path.display()
                            );
                        }
                    }
                }
                Kind::Frames(ext) => {
                    let dir = &ids[k];
                    for (what, path, _) in &inputs {
                        if in_frames(path, dir, ext) {
                            bail_output!(
                                "{} {shown}: holds {what} {}, named like the frames this run \
                                 removes and writes; move it or choose another folder",
                                out.flag,
                                path.display()
                            );
                        }
                    }
                    let others = self.outputs.iter().zip(&ids).enumerate();
                    for (_, (other, other_id)) in others.filter(|(j, _)| *j != k) {
                        let clash = match &other.kind {
                            Kind::File => in_frames(&other.path, dir, ext),
                            Kind::Frames(e) => e == ext && other_id == dir,
                        };
                        if clash {
                            bail_output!(
                                "{} {}: would be among the frames of {} {shown}, which the run \
                                 removes and writes; choose another name",
                                other.flag,
                                other.path.display(),
                                out.flag
                            );
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

/// Whether `path` lies directly in the folder `dir` and is named like one of its frames.
fn in_frames(path: &Path, dir: &Id, ext: &str) -> bool {
    if matches!(
        destination(path, ""),
        Ok(Destination::Stdout | Destination::Stream(_))
    ) {
        return false;
    }
    let full = resolved(path);
    let named = full
        .file_name()
        .is_some_and(|n| super::is_frame_name(&n.to_string_lossy(), ext));
    named && folder_id(path) == *dir
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("hooke-claims-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn refused(claims: &Claims) -> String {
        format!("{:#}", claims.check().unwrap_err())
    }

    #[test]
    fn outputs_meet_inputs_by_identity_not_spelling() {
        let dir = scratch("identity");
        let scene = dir.join("s.toml");
        std::fs::write(&scene, "").unwrap();
        std::os::unix::fs::symlink(&scene, dir.join("link.toml")).unwrap();
        std::fs::hard_link(&scene, dir.join("hard.toml")).unwrap();
        std::fs::create_dir(dir.join("sub")).unwrap();
        for spelling in [
            dir.join("link.toml"),
            dir.join("hard.toml"),
            dir.join("sub/../s.toml"),
        ] {
            let mut c = Claims::default();
            c.input("the scene file", &scene);
            c.file("--trajectory", &spelling);
            assert!(refused(&c).contains("which this run reads"), "{spelling:?}");
        }
        // Two new files of one name, spelled differently.
        let mut c = Claims::default();
        c.file("--trajectory", &dir.join("a.usda"));
        c.file("--export", &dir.join("sub/../a.usda"));
        assert!(refused(&c).contains("same file"), "{}", refused(&c));
        let mut c = Claims::default();
        c.file("--trajectory", Path::new("-"));
        c.file("--gif", Path::new("-"));
        assert!(refused(&c).contains("standard output"));
        let mut c = Claims::default();
        c.file("--trajectory", Path::new("/dev/null"));
        c.file("--gif", Path::new("/dev/null"));
        c.check().unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn frame_folders_claim_their_frame_names() {
        let dir = scratch("frames");
        std::fs::create_dir(dir.join("f")).unwrap();
        let mesh = dir.join("f/frame-00000.obj");
        std::fs::write(&mesh, "").unwrap();
        let mut c = Claims::default();
        c.input("the table mesh", &mesh);
        c.frames("--export", &dir.join("f"), "obj");
        assert!(
            refused(&c).contains("holds the table mesh"),
            "{}",
            refused(&c)
        );
        // A PNG folder does not remove OBJ files.
        let mut c = Claims::default();
        c.input("the table mesh", &mesh);
        c.frames("--frames", &dir.join("f"), "png");
        c.check().unwrap();
        // An output among the frames, and two folders of the same frames, in a folder that
        // does not exist yet.
        let mut c = Claims::default();
        c.frames("--frames", &dir.join("new"), "png");
        c.file("--trajectory", &dir.join("new/../new/frame-00003.png"));
        assert!(refused(&c).contains("among the frames"), "{}", refused(&c));
        let mut c = Claims::default();
        c.frames("--frames", &dir.join("new"), "png");
        c.frames("--frames", &dir.join("./new/"), "png");
        assert!(refused(&c).contains("among the frames"));
        let mut c = Claims::default();
        c.frames("--frames", &dir.join("f"), "png");
        c.frames("--export", &dir.join("f/"), "ply");
        c.check().unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
