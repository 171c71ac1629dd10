//! `--export NAME.pc2`: Blender's point cache (the format of its Mesh Cache modifier) for
//! one body, and `NAME.obj`, that body's mesh at the start, beside it, so that the cloth
//! comes into Blender without a plug-in: import the OBJ, add a Mesh Cache modifier, pick the
//! PC2.
//!
//! The format, all little-endian: a 32-byte header — the 12 bytes `POINTCACHE2\0`, `i32`
//! version 1, `i32` point count, `f32` start frame, `f32` sampling (frames per sample),
//! `i32` sample count — then per sample the points as `f32` triples. Sample `k` is frame `k`
//! of the run (start frame 0, sampling 1). The points are the body's vertices in order (the
//! OBJ's vertices: a body made from a mesh keeps its file's, in their count and order), in metres, +Y up. Blender's OBJ importer turns +Y up into its +Z up on
//! the object, and the cache, read with the modifier's default axes, follows the object;
//! Blender's Mesh Cache modifier ignores the header's start frame and puts sample 0 at its
//! own Frame Start (0 by default, while a timeline starts at 1).
//!
//! Samples are appended as the run goes; the count in the header is written when the run
//! ends, at the last complete frame. `--export DIR/ --format pc2` writes one per body
//! ([`Pc2Folder`]).

use crate::error::{Context, Result, bail_output};
use crate::output::OutputFile;
use hooke_scene::{Body, Scene};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// The header's first 12 bytes.
pub const MAGIC: &[u8; 12] = b"POINTCACHE2\0";
/// Where the sample count sits in the header.
const COUNT_OFFSET: u64 = 28;
/// The header's length in bytes.
pub const HEADER_BYTES: u64 = 32;

/// The last line of the mesh a cache writes beside it: this prefix and a hash of every
/// line before it, so that a later export knows the file for its own and unchanged.
const SIGNATURE: &str = "# hooke mesh, fnv-1a of the lines above: ";

/// The 64-bit FNV-1a hash of `bytes`.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Whether the text of `mesh` is a mesh an export wrote and nobody changed since: its last
/// line is [`SIGNATURE`] with the hash of the lines above it.
fn written_by_hooke(text: &str) -> bool {
    let body = text.strip_suffix('\n').unwrap_or(text);
    let Some(cut) = body.rfind('\n') else {
        return false;
    };
    let (above, last) = (&text[..=cut], &body[cut + 1..]);
    last.strip_prefix(SIGNATURE)
        .and_then(|h| u64::from_str_radix(h, 16).ok())
        .is_some_and(|h| h == fnv1a(above.as_bytes()))
}

/// Refuses to write the cache `pc2`'s mesh over a file at `mesh` that an earlier export did
/// not write, or that was changed since: the user's own OBJ (a cloth made from `flag.obj`,
/// exported as `flag.pc2`) is never replaced.
fn refuse_foreign_mesh(pc2: &Path, mesh: &Path) -> Result<()> {
    let Ok(meta) = std::fs::symlink_metadata(mesh) else {
        return Ok(());
    };
    // Links, devices and the like are refused, by name, when the file is created.
    if !meta.is_file() {
        return Ok(());
    }
    let ours = hooke_core::text::read_text(mesh).is_ok_and(|t| written_by_hooke(&t));
    if !ours {
        bail_output!(
            "--export {}: its mesh goes to {}, which is already there and was not written by \
             an earlier export (or was changed since); hooke does not replace it: move it, or \
             export under another name",
            pc2.display(),
            mesh.display()
        );
    }
    Ok(())
}

/// A point cache being written.
pub struct Pc2Export {
    path: PathBuf,
    file: OutputFile,
    body: String,
    /// The body's index in the scene.
    index: usize,
    /// Reused from frame to frame.
    points: Vec<hooke_core::Vec3>,
    /// Points per sample.
    count: u32,
    samples: u32,
}

/// The body a cache holds: the one named, or the first.
fn pick<'a>(scene: &'a Scene, name: Option<&str>) -> Result<&'a Body> {
    match name {
        None => match scene.bodies.first() {
            Some(b) => Ok(b),
            None => bail_output!("--export: scene {} has no body to cache", scene.spec.name),
        },
        Some(name) => match scene.bodies.iter().find(|b| b.name == name) {
            Some(b) => Ok(b),
            None => {
                let names: Vec<&str> = scene.bodies.iter().map(|b| b.name.as_str()).collect();
                bail_output!(
                    "--body {name}: scene {} has no such body; it has {}",
                    scene.spec.name,
                    names.join(", ")
                )
            }
        },
    }
}

impl Pc2Export {
    /// Starts the cache `path` of body `body` (or the first) of `scene`, and writes the
    /// body's mesh as it is now to the `.obj` beside it.
    pub fn create(path: &Path, body: Option<&str>, scene: &Scene) -> Result<Self> {
        let body = pick(scene, body)?;
        let points = u32::try_from(body.vertex_count())
            .ok()
            .filter(|&n| n <= i32::MAX as u32)
            .ok_or_else(|| {
                crate::Error::output(format!(
                    "--export: body {} is too large for a PC2",
                    body.name
                ))
            })?;
        let mesh = path.with_extension("obj");
        refuse_foreign_mesh(path, &mesh)?;
        let mut obj = OutputFile::create_named(&mesh, "--export (its mesh)")?;
        let sim = &scene.simulation;
        let x = &sim.particles().x;
        let springs = &sim.model().springs;
        (|| -> std::io::Result<()> {
            let mut text = Vec::new();
            writeln!(
                text,
                "# hooke: scene {}, body {} at the start (the mesh of {}), metres, +Y up",
                scene.spec.name,
                body.name,
                path.file_name().unwrap_or_default().to_string_lossy()
            )?;
            super::obj::write_body(&mut text, body, x, springs, Default::default())?;
            let w = obj.writer();
            w.write_all(&text)?;
            writeln!(w, "{SIGNATURE}{:016x}", fnv1a(&text))
        })()
        .with_context(|| format!("cannot write {}", mesh.display()))?;
        obj.commit()?;
        let mut file = OutputFile::create(path)?;
        let w = file.writer();
        let header = (|| -> std::io::Result<()> {
            w.write_all(MAGIC)?;
            w.write_all(&1i32.to_le_bytes())?;
            w.write_all(&(points as i32).to_le_bytes())?;
            w.write_all(&0f32.to_le_bytes())?;
            w.write_all(&1f32.to_le_bytes())?;
            w.write_all(&0i32.to_le_bytes())
        })();
        header.with_context(|| format!("cannot write {}", path.display()))?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            body: body.name.clone(),
            index: scene
                .bodies
                .iter()
                .position(|b| b.name == body.name)
                .unwrap_or(0),
            points: Vec::new(),
            count: points,
            samples: 0,
        })
    }
}

impl crate::Sink for Pc2Export {
    /// Appends frame `frame` of `scene` as the next sample.
    fn frame(&mut self, frame: u64, scene: &Scene) -> Result<()> {
        debug_assert_eq!(frame, u64::from(self.samples));
        scene.bodies[self.index].vertices(&scene.simulation.particles().x, &mut self.points);
        let w = self.file.writer();
        let mut bytes = [0u8; 12];
        for p in &self.points {
            for (k, c) in super::f32s(p).iter().enumerate() {
                bytes[4 * k..4 * k + 4].copy_from_slice(&c.to_le_bytes());
            }
            w.write_all(&bytes)
                .with_context(|| format!("cannot write {}", self.path.display()))?;
        }
        self.samples += 1;
        Ok(())
    }

    /// Writes the sample count and puts the cache in place.
    fn finish(mut self: Box<Self>) -> Result<String> {
        let samples = self.samples as i32;
        let w = self.file.writer();
        (|| -> std::io::Result<()> {
            w.seek(SeekFrom::Start(COUNT_OFFSET))?;
            w.write_all(&samples.to_le_bytes())
        })()
        .with_context(|| format!("cannot write {}", self.path.display()))?;
        self.file.commit()?;
        Ok(format!(
            "{} ({} sample{} of body {}, {} points) and its mesh {}",
            self.path.display(),
            samples,
            if samples == 1 { "" } else { "s" },
            self.body,
            self.count,
            self.path.with_extension("obj").display()
        ))
    }
}

/// Why `name` cannot name a body's cache in a folder (none when it can): a file name of
/// its own, with no separator, control character or leading dot.
fn unfit_file_name(name: &str) -> Option<&'static str> {
    if name.is_empty() {
        Some("it is empty")
    } else if name.starts_with('.') {
        Some("it starts with a dot (a hidden file, or the folder itself)")
    } else if name.contains(['/', '\\']) {
        Some("it holds a path separator")
    } else if name.chars().any(char::is_control) {
        Some("it holds a control character")
    } else {
        None
    }
}

/// Each body of `scene` with the cache it gets in `dir`: `DIR/NAME.pc2`; refused, naming
/// the body, when a name cannot be a file's.
pub fn body_paths(dir: &Path, scene: &Scene) -> Result<Vec<(String, PathBuf)>> {
    if scene.bodies.is_empty() {
        bail_output!("--export: scene {} has no body to cache", scene.spec.name);
    }
    scene
        .bodies
        .iter()
        .map(|b| match unfit_file_name(&b.name) {
            Some(why) => bail_output!(
                "--export {} --format pc2: body '{}' cannot name its cache, {why}: rename the \
                 body, or export it alone with --export FILE.pc2 --body NAME",
                dir.display(),
                b.name.escape_debug()
            ),
            None => Ok((b.name.clone(), dir.join(format!("{}.pc2", b.name)))),
        })
        .collect()
}

/// `--export DIR/ --format pc2`: a point cache per body, `DIR/NAME.pc2` with its mesh
/// `DIR/NAME.obj`, each as [`Pc2Export`] writes one, from one run (bodies that collide with
/// each other, baked together).
pub struct Pc2Folder {
    caches: Vec<Pc2Export>,
    _lock: crate::output::lock::FolderLock,
}

impl Pc2Folder {
    /// Starts the caches of every body of `scene` in `dir` (made if missing), each checked
    /// as a `.pc2` export's file is: no device, link or stream, and no mesh beside it that
    /// an earlier export did not write.
    pub fn create(dir: &Path, scene: &Scene) -> Result<Self> {
        let paths = body_paths(dir, scene)?;
        crate::output::create_folder(dir, "--export")?;
        let lock = crate::output::lock::FolderLock::take(dir, "--export")?;
        for (_, path) in &paths {
            if crate::output::check_output_file(path, "--export", &["pc2"])?.is_stream() {
                bail_output!(
                    "--export {}: a point cache needs a regular file, not a stream",
                    path.display()
                );
            }
            let mesh = path.with_extension("obj");
            crate::output::check_named(&mesh, "--export (its mesh)")?;
            crate::output::check_output_file(&mesh, "--export (its mesh)", &["obj"])?;
            refuse_foreign_mesh(path, &mesh)?;
        }
        let caches = paths
            .iter()
            .map(|(name, path)| Pc2Export::create(path, Some(name), scene))
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            caches,
            _lock: lock,
        })
    }
}

impl crate::Sink for Pc2Folder {
    /// Appends frame `frame` of `scene` to every body's cache.
    fn frame(&mut self, frame: u64, scene: &Scene) -> Result<()> {
        self.caches
            .iter_mut()
            .try_for_each(|c| crate::Sink::frame(c, frame, scene))
    }

    /// Puts every cache in place.
    fn finish(self: Box<Self>) -> Result<String> {
        let Self { caches, _lock } = *self;
        let written = caches
            .into_iter()
            .map(|c| crate::Sink::finish(Box::new(c)))
            .collect::<Result<Vec<_>>>()?;
        Ok(written.join("; "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exports_mesh_is_known_by_its_signature_and_a_changed_one_is_not() {
        let above = "# hooke: scene flag\no body:flag\nv 0 0 0\n";
        let ours = format!("{above}{SIGNATURE}{:016x}\n", fnv1a(above.as_bytes()));
        assert!(written_by_hooke(&ours));
        assert!(!written_by_hooke(&ours.replace("v 0 0 0", "v 0 0 1")));
        assert!(!written_by_hooke(above));
        assert!(!written_by_hooke(""));
    }
}
