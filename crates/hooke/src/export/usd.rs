//! `--export NAME.usda`: the run as one USD stage in USD's text format, written by Hooke
//! itself (no crate writes `.usda`; the text format is small and stable, and the tests open
//! every file with USD's own Python module, `usd-core` from PyPI).
//!
//! The stage is Y-up in metres (`upAxis = "Y"`, `metersPerUnit = 1`); time code `k` is frame
//! `k` of the run and `timeCodesPerSecond` the scene's frame rate, so it plays in real time.
//! Under `/World`, in the scene's order, each body is a prim named after it (characters a
//! USD name cannot hold become `_`):
//!
//! * a body with a surface is a `Mesh` with fixed topology (`faceVertexCounts`,
//!   `faceVertexIndices`) and time-sampled `points`, `velocities` and `extent`;
//! * a chain is a linear `BasisCurves` through its particles, time-sampled the same way;
//! * loose particles are `Points`.
//!
//! A body's points are its particles in order; a body made from a mesh has its file's
//! vertices in their count and order, its faces as written (quads stay quads) and its
//! texture coordinates as `primvars:st`, per face corner. The colliders are meshes under
//! `/World/colliders` where the scene placed them (see [`super::collider_triangles`]); a
//! moving one has a time-sampled `xformOp:transform` with its pose at each frame, a
//! deforming one (a mesh its cache animates) time-sampled `points`. Positions and velocities are
//! `float` as the schemas declare them, each the `f32` nearest the simulation's `f64`.
//!
//! A time-sampled attribute holds all its frames in one block, so the frames cannot go
//! straight into the stage as the run makes them: each body's samples are appended to
//! scratch files beside the target as the run goes, and copied into the stage, block by
//! block, when it ends. Memory stays flat however long the run.

use super::{Shape, shape};
use crate::error::{Context, Result};
use crate::output::OutputFile;
use hooke_core::{Num, Vec3};
use hooke_scene::Scene;
use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Display colours of bodies and colliders, as the stills draw them.
const BODY_COLOUR: [f32; 3] = [0.85, 0.33, 0.25];
const COLLIDER_COLOUR: [f32; 3] = [0.6, 0.6, 0.62];
/// Width of exported curves and points, metres.
const CURVE_WIDTH: f64 = 0.01;
const POINT_WIDTH: f64 = 0.05;

/// An `f32` in a form USD reads back as the same `f32`: Rust's shortest round-trip digits,
/// in exponent form far from 1.
struct F(f32);

impl std::fmt::Display for F {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || (1e-4..1e7).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// The `f32` nearest `x`, moved one step down (`up`: up) when that is not beyond `x`.
fn outward(x: f64, up: bool) -> f32 {
    let c = x as f32;
    match (up, (c as f64).partial_cmp(&x)) {
        (true, Some(std::cmp::Ordering::Less)) => c.next_up(),
        (false, Some(std::cmp::Ordering::Greater)) => c.next_down(),
        _ => c,
    }
}

/// `(x, y, z)` as USD writes a 3-vector.
fn tuple(v: [f32; 3]) -> String {
    format!("({}, {}, {})", F(v[0]), F(v[1]), F(v[2]))
}

/// A USD prim name made of `name`: letters, digits and `_`, not starting with a digit.
fn prim_name(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, '_');
    }
    s
}

/// One body's time samples, streamed to scratch files until the stage is assembled.
struct BodyStream {
    /// The prim's opening and its static attributes (topology, widths, colour).
    opening: String,
    /// Scratch files of the `points`, `velocities` and `extent` samples.
    points: OutputFile,
    velocities: OutputFile,
    extent: OutputFile,
}

/// A USD stage being written.
pub struct UsdExport {
    path: PathBuf,
    scene: String,
    bodies: Vec<BodyStream>,
    /// The colliders' prims, each a `{transform}` slot where a moving or deforming one's
    /// samples go.
    colliders: Vec<String>,
    /// Per collider: its `xformOp:transform` samples so far, or a deforming one's `points`
    /// samples (empty for a still one).
    transforms: Vec<String>,
    /// Per collider, whether a cache deforms it (its samples are points, not transforms).
    deforming: Vec<bool>,
    frames: u64,
    /// Seconds between frames.
    frame_time: f64,
    /// A body's vertex positions and velocities, reused from frame to frame.
    x: Vec<Vec3>,
    v: Vec<Vec3>,
}

impl UsdExport {
    /// Starts the stage `path` for `scene`.
    pub fn create(path: &Path, scene: &Scene) -> Result<Self> {
        let mut taken: Vec<String> = vec!["colliders".into()];
        let mut bodies = Vec::new();
        for (k, body) in scene.bodies.iter().enumerate() {
            let mut prim = prim_name(&body.name);
            // Two names can map to one prim name: number the later one.
            if taken.contains(&prim) {
                prim = format!("{prim}_{k}");
            }
            taken.push(prim.clone());
            // Hidden temporary files beside the stage (or in the system's temporary folder
            // for a stream), so that no file of another name is written beside it.
            bodies.push(BodyStream {
                opening: opening(&prim, body)?,
                points: OutputFile::scratch(path)?,
                velocities: OutputFile::scratch(path)?,
                extent: OutputFile::scratch(path)?,
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            scene: scene.spec.name.clone(),
            bodies,
            colliders: colliders(scene)?,
            transforms: vec![String::new(); scene.colliders.len()],
            deforming: (0..scene.colliders.len())
                .map(|k| scene.animations.get(k).is_some_and(Option::is_some))
                .collect(),
            frames: 0,
            frame_time: scene.every as f64 * scene.simulation.dt(),
            x: Vec::new(),
            v: Vec::new(),
        })
    }

    fn assemble(&mut self, file: &mut OutputFile) -> Result<()> {
        let fps = Num(1.0 / self.frame_time);
        let w = file.writer();
        writeln!(w, "#usda 1.0\n(")?;
        writeln!(
            w,
            "    doc = \"Hooke: scene {}, {} frames, frame k at time code k\"",
            self.scene.replace(['"', '\\'], "_"),
            self.frames
        )?;
        writeln!(w, "    defaultPrim = \"World\"")?;
        writeln!(w, "    metersPerUnit = 1")?;
        writeln!(w, "    upAxis = \"Y\"")?;
        writeln!(w, "    startTimeCode = 0")?;
        writeln!(w, "    endTimeCode = {}", self.frames.saturating_sub(1))?;
        writeln!(w, "    timeCodesPerSecond = {fps}")?;
        writeln!(w, "    framesPerSecond = {fps}")?;
        writeln!(w, ")\n\ndef Xform \"World\"\n{{")?;
        for stream in &mut self.bodies {
            file.writer().write_all(stream.opening.as_bytes())?;
            for (declaration, scratch) in [
                ("point3f[] points", &mut stream.points),
                ("vector3f[] velocities", &mut stream.velocities),
                ("float3[] extent", &mut stream.extent),
            ] {
                let mut samples = scratch.read_back()?;
                let w = file.writer();
                writeln!(w, "        {declaration}.timeSamples = {{")?;
                std::io::copy(&mut samples, w)?;
                writeln!(w, "        }}")?;
            }
            writeln!(file.writer(), "    }}")?;
        }
        writeln!(file.writer(), "    def Xform \"colliders\"\n    {{")?;
        for ((prim, samples), deforming) in self
            .colliders
            .iter()
            .zip(&self.transforms)
            .zip(&self.deforming)
        {
            let transform = if samples.is_empty() {
                String::new()
            } else if *deforming {
                format!("            point3f[] points.timeSamples = {{\n{samples}            }}\n")
            } else {
                format!(
                    "            matrix4d xformOp:transform.timeSamples = {{\n{samples}            }}\n\
                     \x20           uniform token[] xformOpOrder = [\"xformOp:transform\"]\n"
                )
            };
            file.writer()
                .write_all(prim.replace("{transform}", &transform).as_bytes())?;
        }
        writeln!(file.writer(), "    }}\n}}")?;
        Ok(())
    }
}

/// A body prim's opening: its type and name, and its attributes that do not change.
fn opening(prim: &str, body: &hooke_scene::Body) -> Result<String> {
    let mut s = String::new();
    let n = body.vertex_count();
    match shape(body) {
        Shape::Mesh(faces) => {
            writeln!(s, "    def Mesh \"{prim}\"\n    {{")?;
            writeln!(s, "        uniform token subdivisionScheme = \"none\"")?;
            let counts: Vec<String> = faces.iter().map(|f| f.len().to_string()).collect();
            writeln!(
                s,
                "        int[] faceVertexCounts = [{}]",
                counts.join(", ")
            )?;
            let indices: Vec<String> = faces.iter().flatten().map(|i| i.to_string()).collect();
            writeln!(
                s,
                "        int[] faceVertexIndices = [{}]",
                indices.join(", ")
            )?;
            // A mesh's texture coordinates, per face corner, when every face has them.
            if let Some(skin) = &body.skin
                && !skin.faces.is_empty()
                && skin.faces.iter().all(|f| f.uvs.is_some())
            {
                let st: Vec<String> = skin
                    .faces
                    .iter()
                    .flat_map(|f| f.uvs.iter().flatten())
                    .map(|&t| {
                        let [u, v] = skin.uvs[t as usize];
                        format!("({}, {})", F(u as f32), F(v as f32))
                    })
                    .collect();
                writeln!(
                    s,
                    "        texCoord2f[] primvars:st = [{}] (interpolation = \"faceVarying\")",
                    st.join(", ")
                )?;
            }
        }
        Shape::Curve => {
            writeln!(s, "    def BasisCurves \"{prim}\"\n    {{")?;
            writeln!(s, "        uniform token type = \"linear\"")?;
            writeln!(s, "        int[] curveVertexCounts = [{n}]")?;
            let width = Num(CURVE_WIDTH);
            writeln!(
                s,
                "        float[] widths = [{width}] (interpolation = \"constant\")"
            )?;
        }
        Shape::Points => {
            writeln!(s, "    def Points \"{prim}\"\n    {{")?;
            let width = Num(POINT_WIDTH);
            writeln!(
                s,
                "        float[] widths = [{width}] (interpolation = \"constant\")"
            )?;
        }
    }
    let colour = tuple(BODY_COLOUR);
    writeln!(s, "        color3f[] primvars:displayColor = [{colour}]")?;
    Ok(s)
}

/// The colliders' meshes where the scene placed them, one prim each, for `colliders`; a
/// moving one's transform samples go in its `{transform}` slot.
fn colliders(scene: &Scene) -> Result<Vec<String>> {
    let mut out = Vec::new();
    for (name, triangles) in super::collider_triangles(scene) {
        let mut s = String::new();
        writeln!(
            s,
            "        def Mesh \"{}\"\n        {{",
            prim_name(&format!("c{name}"))
        )?;
        writeln!(s, "            uniform token subdivisionScheme = \"none\"")?;
        let points: Vec<String> = triangles
            .iter()
            .flatten()
            .map(|p| tuple(super::f32s(p)))
            .collect();
        writeln!(s, "            point3f[] points = [{}]", points.join(", "))?;
        let counts = vec!["3"; triangles.len()].join(", ");
        writeln!(s, "            int[] faceVertexCounts = [{counts}]")?;
        let indices: Vec<String> = (0..3 * triangles.len()).map(|i| i.to_string()).collect();
        writeln!(
            s,
            "            int[] faceVertexIndices = [{}]",
            indices.join(", ")
        )?;
        let colour = tuple(COLLIDER_COLOUR);
        writeln!(
            s,
            "            color3f[] primvars:displayColor = [{colour}]"
        )?;
        s.push_str("{transform}");
        writeln!(s, "        }}")?;
        out.push(s);
    }
    Ok(out)
}

/// A moving collider's pose as USD's row-vector matrix: `p' = p M`, so the rotation is
/// transposed and the translation `pivot + T − R pivot` is the last row.
fn pose_matrix(pose: &hooke_scene::ColliderPose) -> String {
    let origin = pose.place(&Vec3::zeros());
    let axes = [Vec3::x(), Vec3::y(), Vec3::z()].map(|e| pose.place(&e) - origin);
    let row = |v: Vec3, w: u8| format!("({}, {}, {}, {w})", Num(v.x), Num(v.y), Num(v.z));
    format!(
        "({}, {}, {}, {})",
        row(axes[0], 0),
        row(axes[1], 0),
        row(axes[2], 0),
        row(origin, 1)
    )
}

impl crate::Sink for UsdExport {
    /// Appends frame `frame` of `scene` to every body's samples.
    fn frame(&mut self, frame: u64, scene: &Scene) -> Result<()> {
        let p = scene.simulation.particles();
        for (body, stream) in scene.bodies.iter().zip(&mut self.bodies) {
            body.vertices(&p.x, &mut self.x);
            body.vertex_velocities(&p.v, &mut self.v);
            let write = |file: &mut OutputFile, values: &mut dyn Iterator<Item = [f32; 3]>| {
                let w = file.writer();
                write!(w, "            {frame}: [")?;
                for (k, v) in values.enumerate() {
                    if k > 0 {
                        w.write_all(b", ")?;
                    }
                    write!(w, "({}, {}, {})", F(v[0]), F(v[1]), F(v[2]))?;
                }
                w.write_all(b"],\n")
            };
            let (lo, hi) = self.x.iter().fold(
                (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |(lo, hi), x| (lo.inf(x), hi.sup(x)),
            );
            (|| -> std::io::Result<()> {
                write(&mut stream.points, &mut self.x.iter().map(super::f32s))?;
                write(&mut stream.velocities, &mut self.v.iter().map(super::f32s))?;
                // The extent holds every point: rounded outwards to f32.
                let (lo, hi) = (lo.map(|c| outward(c, false)), hi.map(|c| outward(c, true)));
                write(
                    &mut stream.extent,
                    &mut [[lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]].into_iter(),
                )
            })()
            .with_context(|| format!("cannot write the samples of {}", self.path.display()))?;
        }
        let t = scene.simulation.time();
        for (k, samples) in self.transforms.iter_mut().enumerate() {
            if let Some(triangles) = scene.collider_triangles_at(k, t) {
                let points: Vec<String> = triangles
                    .iter()
                    .flatten()
                    .map(|p| tuple(super::f32s(p)))
                    .collect();
                let _ = writeln!(samples, "                {frame}: [{}],", points.join(", "));
            } else if let Some(pose) = scene.collider_pose(k, t) {
                let _ = writeln!(samples, "                {frame}: {},", pose_matrix(&pose));
            }
        }
        self.frames += 1;
        Ok(())
    }

    /// Assembles the stage from the samples written so far and puts it in place.
    fn finish(mut self: Box<Self>) -> Result<String> {
        let mut file = OutputFile::create(&self.path)?;
        self.assemble(&mut file)
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        file.commit()?;
        Ok(format!(
            "{} ({} frame{} at {} frames/s)",
            self.path.display(),
            self.frames,
            if self.frames == 1 { "" } else { "s" },
            Num(1.0 / self.frame_time)
        ))
    }
}
