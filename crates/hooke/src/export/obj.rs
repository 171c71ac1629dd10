//! `--export DIR/ --format obj`: one Wavefront OBJ per frame, in world coordinates, so that
//! anyone can check or render the frames with their own tools.
//!
//! `DIR/frame-00000.obj` holds frame 0, and so on. A body made from a mesh is an object
//! `body:<name>` of its file's vertices, in their count and order, with its texture
//! coordinates and faces as written; any other body with a surface is one of its particles'
//! positions and its surface triangles (the triangles the contacts act on); a chain or loose points is an object of its positions with its springs
//! as `l` elements. Each collider is an object `collider:<index>-<kind>` of triangles (see
//! [`super::collider_triangles`]). Numbers are Rust's shortest round-trip numbers
//! ([`hooke_core::Num`]); every file is written whole or not at all.

use crate::error::{Context, Result};
use crate::output::OutputFile;
use hooke_core::{Num, Spring, Vec3};
use hooke_scene::{Body, Scene};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes a scene's frames as OBJ files into one folder.
#[derive(Debug)]
pub struct ObjExport {
    dir: PathBuf,
    /// The folder, held for this run.
    _lock: crate::output::lock::FolderLock,
    /// Frames written.
    frames: u64,
    /// `collider:<index>-<kind>` and its triangles where the scene placed it (moving ones
    /// are posed at each frame's time).
    colliders: Vec<(String, Vec<[Vec3; 3]>)>,
}

impl ObjExport {
    /// Prepares the folder `dir` (created if missing; refused if it is a file) for `scene`,
    /// whose collider surfaces are computed here once.
    pub fn new(dir: &Path, scene: &Scene) -> Result<Self> {
        let lock = super::frame_folder(dir, "obj")?;
        let colliders = super::collider_triangles(scene)
            .into_iter()
            .map(|(name, triangles)| (format!("collider:{name}"), triangles))
            .collect();
        Ok(Self {
            dir: dir.to_path_buf(),
            _lock: lock,
            frames: 0,
            colliders,
        })
    }

    /// The file of frame `frame`.
    pub fn path(&self, frame: u64) -> PathBuf {
        self.dir.join(crate::output::frame_name(frame, "obj"))
    }
}

fn vertex(w: &mut impl Write, p: &Vec3) -> std::io::Result<()> {
    writeln!(w, "v {} {} {}", Num(p.x), Num(p.y), Num(p.z))
}

/// Where the next body's vertices and texture coordinates start in an OBJ file (1-based:
/// one more than the count written before it).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Base {
    /// The next vertex's number.
    pub(crate) vertex: usize,
    /// The next texture coordinate's number.
    pub(crate) uv: usize,
}

impl Default for Base {
    fn default() -> Self {
        Self { vertex: 1, uv: 1 }
    }
}

/// Writes `body` as the object `body:<name>`: the vertices it shows at the particles'
/// positions `x` (a mesh body's are its file's, in their order, with its texture
/// coordinates), numbered from `base`, and its faces (a mesh body's as written, quads
/// staying quads), or for a body without faces its `springs` as lines. Returns where the
/// next body starts.
pub(crate) fn write_body(
    w: &mut impl Write,
    body: &Body,
    x: &[Vec3],
    springs: &[Spring],
    base: Base,
) -> std::io::Result<Base> {
    writeln!(w, "o body:{}", body.name)?;
    let mut points = Vec::new();
    body.vertices(x, &mut points);
    for p in &points {
        vertex(w, p)?;
    }
    let uvs = body.skin.as_ref().map_or(&[][..], |s| &s.uvs[..]);
    for t in uvs {
        writeln!(w, "vt {} {}", Num(t[0]), Num(t[1]))?;
    }
    match &body.skin {
        Some(skin) => {
            for f in &skin.faces {
                write!(w, "f")?;
                for (k, &c) in f.corners.iter().enumerate() {
                    match &f.uvs {
                        Some(t) => write!(
                            w,
                            " {}/{}",
                            c as usize + base.vertex,
                            t[k] as usize + base.uv
                        )?,
                        None => write!(w, " {}", c as usize + base.vertex)?,
                    }
                }
                writeln!(w)?;
            }
        }
        None => {
            let local = |i: u32| i as usize - body.range.start + base.vertex;
            for t in &body.triangles {
                writeln!(w, "f {} {} {}", local(t[0]), local(t[1]), local(t[2]))?;
            }
            if body.triangles.is_empty() {
                for s in springs
                    .iter()
                    .filter(|s| body.range.contains(&(s.i as usize)))
                {
                    writeln!(w, "l {} {}", local(s.i), local(s.j))?;
                }
            }
        }
    }
    Ok(Base {
        vertex: base.vertex + points.len(),
        uv: base.uv + uvs.len(),
    })
}

fn write_frame(
    w: &mut impl Write,
    frame: u64,
    scene: &Scene,
    colliders: &[(String, Vec<[Vec3; 3]>)],
) -> std::io::Result<()> {
    let sim = &scene.simulation;
    let x = &sim.particles().x;
    writeln!(
        w,
        "# hooke: scene {}, frame {frame}, t = {} s, metres, +Y up",
        scene.spec.name,
        Num(sim.time())
    )?;
    // OBJ indices are 1-based and count every vertex written so far in the file.
    let mut next = Base::default();
    for body in &scene.bodies {
        next = write_body(w, body, x, &sim.model().springs, next)?;
    }
    let mut base = next.vertex;
    for (name, tris) in colliders {
        writeln!(w, "o {name}")?;
        for t in tris {
            for p in t {
                vertex(w, p)?;
            }
        }
        for k in 0..tris.len() {
            let v = base + 3 * k;
            writeln!(w, "f {} {} {}", v, v + 1, v + 2)?;
        }
        base += 3 * tris.len();
    }
    Ok(())
}

impl crate::Sink for ObjExport {
    /// Writes frame `frame` of `scene` at its current state.
    fn frame(&mut self, frame: u64, scene: &Scene) -> Result<()> {
        let path = self.path(frame);
        let mut file = OutputFile::create_named(&path, "--export")?;
        let posed;
        let colliders = if scene.has_moving_colliders() {
            posed = super::posed(scene, &self.colliders);
            &posed
        } else {
            &self.colliders
        };
        write_frame(file.writer(), frame, scene, colliders)
            .with_context(|| format!("cannot write {}", path.display()))?;
        file.commit()?;
        crate::output::record_frame(&path, "--export")?;
        self.frames += 1;
        Ok(())
    }

    /// What was written, for the run's report.
    fn finish(self: Box<Self>) -> Result<String> {
        Ok(super::frames_written("OBJ", self.frames, &self.dir))
    }
}
