//! `hooke run SCENE --export PATH`: a run's frames in the formats other tools render from,
//! written as the run goes (memory does not grow with the frame count), each file whole or
//! not at all, and complete up to the last frame when a run is interrupted or diverges.
//!
//! The format follows the path:
//!
//! * `NAME.usda`: one USD stage ([`usd`]), Y-up, metres, a time code per frame;
//! * `NAME.pc2`: Blender's point cache for one body ([`pc2`]), with `NAME.obj`, the body's
//!   mesh at the start, beside it;
//! * `DIR/` with `--format ply` or `--format obj`: a file per frame, `DIR/frame-00000.ply`
//!   … ([`ply`], [`obj`]);
//! * `DIR/` with `--format pc2`: a point cache per body, `DIR/NAME.pc2` with its mesh
//!   `DIR/NAME.obj` ([`pc2::Pc2Folder`]), so that bodies simulated together (two garments
//!   that collide) come into Blender from one run.
//!
//! Coordinates are the simulation's: metres, +Y up.

pub mod obj;
pub mod pc2;
pub mod ply;
#[cfg(feature = "export-usd")]
pub mod usd;

use crate::error::{Result, bail_output};
use crate::output::{check_output_file, check_output_folder};
use hooke_core::Vec3;
use hooke_scene::{Body, ColliderGeometry, Scene, Topology};
use std::path::{Path, PathBuf};

/// The format of a folder export (`--format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum FolderFormat {
    /// Binary little-endian PLY: vertices with normals, triangles.
    Ply,
    /// Wavefront OBJ: bodies and colliders as named objects.
    Obj,
    /// Blender's point cache of every body, `NAME.pc2`, with its mesh `NAME.obj` (not a
    /// file per frame: a cache per body).
    Pc2,
}

impl FolderFormat {
    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Ply => "ply",
            Self::Obj => "obj",
            Self::Pc2 => "pc2",
        }
    }
}

/// Where a run is exported, decided from `--export PATH` before the scene is built.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// A USD stage.
    Usd(PathBuf),
    /// A Blender point cache of one body (the named one, or the first), and its mesh.
    Pc2 {
        /// The `.pc2` file.
        path: PathBuf,
        /// The body's name, if one was asked for.
        body: Option<String>,
    },
    /// A file per frame in a folder.
    Folder {
        /// The folder.
        dir: PathBuf,
        /// The files' format.
        format: FolderFormat,
    },
}

impl Target {
    /// The target `--export path` names, with `--format` and `--body` if given; refused with
    /// what was expected when the combination makes no sense or the path cannot be written.
    ///
    /// ```
    /// use hooke::export::{FolderFormat, Target};
    /// use std::path::Path;
    /// let dir = std::env::temp_dir();
    /// let usd = dir.join("run.usda");
    /// assert_eq!(Target::new(&usd, None, None).unwrap(), Target::Usd(usd.clone()));
    /// let frames = format!("{}/frames/", dir.display());
    /// assert!(matches!(
    ///     Target::new(Path::new(&frames), Some(FolderFormat::Ply), None),
    ///     Ok(Target::Folder { format: FolderFormat::Ply, .. })
    /// ));
    /// assert!(Target::new(Path::new(&frames), None, None).is_err()); // which format?
    /// assert!(Target::new(&dir.join("run.fbx"), None, None).is_err());
    /// ```
    pub fn new(path: &Path, format: Option<FolderFormat>, body: Option<&str>) -> Result<Self> {
        let text = path.to_string_lossy();
        let folder =
            text.ends_with('/') || text.ends_with(std::path::MAIN_SEPARATOR) || path.is_dir();
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let target = match (folder, ext.as_str(), format) {
            (true, _, Some(FolderFormat::Pc2)) => {
                check_output_folder(path, "--export")?;
                Target::Folder {
                    dir: path.to_path_buf(),
                    format: FolderFormat::Pc2,
                }
            }
            (true, _, Some(format)) => {
                check_output_folder(path, "--export")?;
                Target::Folder {
                    dir: path.to_path_buf(),
                    format,
                }
            }
            (true, _, None) => bail_output!(
                "--export {}: a folder export needs --format ply, --format obj or --format pc2",
                path.display()
            ),
            (false, "usda" | "pc2", Some(format)) => bail_output!(
                "--format {}: only folder exports (--export DIR/) take a format; {} is a .{ext} \
                 file",
                format.extension(),
                path.display()
            ),
            (false, "usda", None) => {
                check_output_file(path, "--export", &["usda"])?;
                Target::Usd(path.to_path_buf())
            }
            (false, "pc2", None) => {
                if check_output_file(path, "--export", &["pc2"])?.is_stream() {
                    bail_output!(
                        "--export {}: a point cache is written with its sample count at the \
                         start, known only at the end: it needs a regular file, not a stream",
                        path.display()
                    );
                }
                // The mesh's name is chosen by hooke, not by the user: nothing planted there
                // is written through.
                let mesh = path.with_extension("obj");
                crate::output::check_named(&mesh, "--export (its mesh)")?;
                check_output_file(&mesh, "--export (its mesh)", &["obj"])?;
                Target::Pc2 {
                    path: path.to_path_buf(),
                    body: body.map(str::to_string),
                }
            }
            _ => bail_output!(
                "--export {}: expected a file ending in .usda or .pc2, or a folder ending in / \
                 with --format ply, obj or pc2",
                path.display()
            ),
        };
        if body.is_some() && !matches!(target, Target::Pc2 { .. }) {
            bail_output!("--body: only a .pc2 export holds one body; the others hold them all");
        }
        Ok(target)
    }

    /// Adds the files and folders this export writes to `claims`. A point cache per body is
    /// claimed once the scene, and so its bodies' names, are known ([`Target::claim_bodies`]).
    pub fn claim(&self, claims: &mut crate::output::claims::Claims) {
        match self {
            Target::Usd(path) => claims.file("--export", path),
            Target::Pc2 { path, .. } => {
                claims.file("--export", path);
                claims.file("--export (its mesh)", &path.with_extension("obj"));
            }
            Target::Folder {
                format: FolderFormat::Pc2,
                ..
            } => {}
            Target::Folder { dir, format } => claims.frames("--export", dir, format.extension()),
        }
    }

    /// Adds the files a point cache per body writes for `scene` to `claims` (nothing for
    /// other exports); refused when a body's name cannot be a file's.
    pub fn claim_bodies(
        &self,
        scene: &Scene,
        claims: &mut crate::output::claims::Claims,
    ) -> Result<()> {
        if let Target::Folder {
            dir,
            format: FolderFormat::Pc2,
        } = self
        {
            for (_, path) in pc2::body_paths(dir, scene)? {
                claims.file("--export", &path);
                claims.file("--export (its mesh)", &path.with_extension("obj"));
            }
        }
        Ok(())
    }
}

/// Starts exporting `scene` to `target`.
pub fn create(target: &Target, scene: &Scene) -> Result<Box<dyn crate::Sink + Send>> {
    Ok(match target {
        #[cfg(feature = "export-usd")]
        Target::Usd(path) => Box::new(usd::UsdExport::create(path, scene)?),
        #[cfg(not(feature = "export-usd"))]
        Target::Usd(path) => crate::error::bail_output!(
            "--export {}: this build of hooke has no USD export (feature `export-usd`)",
            path.display()
        ),
        Target::Pc2 { path, body } => {
            Box::new(pc2::Pc2Export::create(path, body.as_deref(), scene)?)
        }
        Target::Folder {
            dir,
            format: FolderFormat::Obj,
        } => Box::new(obj::ObjExport::new(dir, scene)?),
        Target::Folder {
            dir,
            format: FolderFormat::Ply,
        } => Box::new(ply::PlyExport::new(dir, scene)?),
        Target::Folder {
            dir,
            format: FolderFormat::Pc2,
        } => Box::new(pc2::Pc2Folder::create(dir, scene)?),
    })
}

/// What a folder export wrote, for the run's report: `N KIND frames in DIR`.
fn frames_written(kind: &str, frames: u64, dir: &Path) -> String {
    format!(
        "{frames} {kind} frame{} in {}",
        if frames == 1 { "" } else { "s" },
        dir.display()
    )
}

/// Prepares `dir` for a folder export's `frame-NNNNN.ext` files (see
/// [`crate::output::prepare_frame_folder`]), saying how many frames of an earlier run it
/// removed; returns the folder's lock.
fn frame_folder(dir: &Path, ext: &str) -> Result<crate::output::lock::FolderLock> {
    let (lock, removed) = crate::output::prepare_frame_folder(dir, "--export", ext)?;
    if removed > 0 {
        eprintln!(
            "--export: removed {removed} frame{} of an earlier run from {}",
            if removed == 1 { "" } else { "s" },
            dir.display()
        );
    }
    Ok(lock)
}

/// What a body becomes outside Hooke.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A mesh: its faces as polygons of indices into the vertices the body shows
    /// ([`Body::vertices`]; a mesh body's quads stay quads).
    Mesh(Vec<Vec<u32>>),
    /// A polyline through its particles in order (a chain).
    Curve,
    /// Loose points.
    Points,
}

/// The shape `body` is exported as.
pub fn shape(body: &Body) -> Shape {
    if body.skin.is_some() || !body.triangles.is_empty() {
        Shape::Mesh(body.faces())
    } else if body.topology == Topology::Chain {
        Shape::Curve
    } else {
        Shape::Points
    }
}

/// Half the side of the exported ground square, metres: larger than any built-in scene's
/// reach.
const GROUND_HALF: f64 = 2.5;

/// Each collider's name (`<index>-<kind>`) and surface as triangles where the scene placed
/// it (see [`posed`] for moving ones): the
/// analytic cylinder tessellated inside the true solid, the ground a square around the
/// bodies' start, an inclined plane clipped to the jello box or a region around the bodies.
pub fn collider_triangles(scene: &Scene) -> Vec<(String, Vec<[Vec3; 3]>)> {
    let x = &scene.simulation.particles().x;
    let (lo, hi) = x.iter().fold(
        (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let centre = if x.is_empty() {
        Vec3::zeros()
    } else {
        (lo + hi) * 0.5
    };
    let region = scene
        .colliders
        .iter()
        .find_map(|c| match c {
            ColliderGeometry::Box(b) => Some((b.min, b.max)),
            _ => None,
        })
        .unwrap_or((
            centre.add_scalar(-GROUND_HALF),
            centre.add_scalar(GROUND_HALF),
        ));
    scene
        .colliders
        .iter()
        .enumerate()
        .map(|(k, c)| {
            (
                format!("{k}-{}", c.kind()),
                c.triangles(centre, GROUND_HALF, region),
            )
        })
        .collect()
}

/// `colliders` (as [`collider_triangles`] gives them, in scene order) with each moving one
/// at its pose at the scene's current time, and each deforming one as its cache has it then.
pub fn posed(
    scene: &Scene,
    colliders: &[(String, Vec<[Vec3; 3]>)],
) -> Vec<(String, Vec<[Vec3; 3]>)> {
    let t = scene.simulation.time();
    colliders
        .iter()
        .enumerate()
        .map(|(k, (name, tris))| match scene.collider_pose(k, t) {
            _ if scene.animations.get(k).is_some_and(Option::is_some) => (
                name.clone(),
                scene.collider_triangles_at(k, t).unwrap_or_default(),
            ),
            Some(pose) => (
                name.clone(),
                tris.iter().map(|tri| tri.map(|p| pose.place(&p))).collect(),
            ),
            None => (name.clone(), tris.clone()),
        })
        .collect()
}

/// Unit vertex normals of `triangles` (indices into `x`): each vertex's sum of its
/// triangles' area-weighted normals, normalised; zero for vertices on no triangle or only on
/// degenerate ones.
pub fn vertex_normals(x: &[Vec3], triangles: &[[u32; 3]], out: &mut Vec<Vec3>) {
    out.clear();
    out.resize(x.len(), Vec3::zeros());
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let n = (x[b] - x[a]).cross(&(x[c] - x[a]));
        for i in [a, b, c] {
            out[i] += n;
        }
    }
    for n in out.iter_mut() {
        let len = n.norm();
        *n = if len > 0.0 { *n / len } else { Vec3::zeros() };
    }
}

/// `x` as the nearest `f32`, as the exported formats store it.
pub fn f32s(x: &Vec3) -> [f32; 3] {
    [x.x as f32, x.y as f32, x.z as f32]
}
