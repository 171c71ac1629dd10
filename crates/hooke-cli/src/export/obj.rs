//! `--export-obj DIR`: one Wavefront OBJ per frame, in world coordinates, so that anyone can
//! check or render the frames with their own tools.
//!
//! `DIR/frame-00000.obj` holds frame 0, and so on. Each body with a surface is an object
//! `body:<name>` of its particles' positions and its surface triangles (the triangles the
//! contacts act on); a chain or loose points is an object of its positions with its springs
//! as `l` elements. Each collider is an object `collider:<index>-<kind>` of triangles: the
//! analytic cylinder tessellated inside the true solid, the ground a square around the
//! bodies' start, an inclined plane clipped to the scene's region. Numbers are Rust's
//! shortest round-trip numbers ([`hooke_core::Num`]); every file is written whole or not at all.

use crate::output::AtomicFile;
use anyhow::{Context, Result};
use hooke_core::{Num, Vec3};
use hooke_scene::Scene;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Half the side of the exported ground square, metres: larger than any built-in scene's
/// reach.
const GROUND_HALF: f64 = 2.5;

/// Writes a scene's frames as OBJ files into one folder.
#[derive(Debug)]
pub struct ObjExport {
    dir: PathBuf,
    /// `collider:<index>-<kind>` and its triangles, which do not move.
    colliders: Vec<(String, Vec<[Vec3; 3]>)>,
}

impl ObjExport {
    /// Prepares the folder `dir` (created if missing; refused if it is a file) for `scene`,
    /// whose collider surfaces are computed here once.
    pub fn new(dir: &Path, scene: &Scene) -> Result<Self> {
        let removed = crate::output::prepare_frame_folder(dir, "--export-obj", "obj")?;
        if removed > 0 {
            eprintln!(
                "--export-obj: removed {removed} frame{} of an earlier run from {}",
                if removed == 1 { "" } else { "s" },
                dir.display()
            );
        }
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
        // Inclined planes are clipped to the jello box when there is one, else to a region
        // around the bodies.
        let region = scene
            .colliders
            .iter()
            .find_map(|c| match c {
                hooke_scene::ColliderGeometry::Box(b) => Some((b.min, b.max)),
                _ => None,
            })
            .unwrap_or((
                centre.add_scalar(-GROUND_HALF),
                centre.add_scalar(GROUND_HALF),
            ));
        let colliders = scene
            .colliders
            .iter()
            .enumerate()
            .map(|(k, c)| {
                (
                    format!("collider:{k}-{}", c.kind()),
                    c.triangles(centre, GROUND_HALF, region),
                )
            })
            .collect();
        Ok(Self {
            dir: dir.to_path_buf(),
            colliders,
        })
    }

    /// The file of frame `frame`.
    pub fn path(&self, frame: u64) -> PathBuf {
        self.dir.join(crate::output::frame_name(frame, "obj"))
    }

    /// Writes frame `frame` of `scene` at its current state.
    pub fn frame(&self, frame: u64, scene: &Scene) -> Result<()> {
        let path = self.path(frame);
        let mut file = AtomicFile::create(&path)?;
        write_frame(file.writer(), frame, scene, &self.colliders)
            .with_context(|| format!("cannot write {}", path.display()))?;
        file.commit()
    }
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
    let mut base = 1usize;
    let vertex =
        |w: &mut dyn Write, p: &Vec3| writeln!(w, "v {} {} {}", Num(p.x), Num(p.y), Num(p.z));
    for body in &scene.bodies {
        writeln!(w, "o body:{}", body.name)?;
        for p in &x[body.range.clone()] {
            vertex(w, p)?;
        }
        let local = |i: u32| i as usize - body.range.start + base;
        for t in &body.triangles {
            writeln!(w, "f {} {} {}", local(t[0]), local(t[1]), local(t[2]))?;
        }
        if body.triangles.is_empty() {
            for s in sim
                .model()
                .springs
                .iter()
                .filter(|s| body.range.contains(&(s.i as usize)))
            {
                writeln!(w, "l {} {}", local(s.i), local(s.j))?;
            }
        }
        base += body.range.len();
    }
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
