//! `--export DIR/ --format ply`: one binary little-endian PLY per frame, written with the
//! `ply-rs-bw` crate (the maintained fork of `ply-rs`).
//!
//! `DIR/frame-00000.ply` holds frame 0, and so on: an element `vertex` per vertex the bodies
//! show, body after body (a generated body's particles in order; a body made from a mesh,
//! its file's vertices in their count and order) with `x y z` and a unit normal `nx ny nz`
//! (the area-weighted normal of its triangles, zero off every surface), and an element
//! `face` with the bodies' faces as `vertex_indices` (a mesh body's as written, quads
//! staying quads) and, when a mesh has them, each corner's texture coordinates as a list
//! `texcoord` of `u v` pairs (empty for faces without). Colliders do not move and are left out (`--format obj`
//! has them). Values are `float`, as renderers read them.

use crate::error::{Context, Result};
use crate::output::OutputFile;
use hooke_core::{Num, Vec3};
use hooke_scene::Scene;
use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Header, PropertyAccess, PropertyDef, PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;
use std::path::{Path, PathBuf};

/// A vertex as the PLY writer reads it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlyVertex {
    /// Position.
    pub x: [f32; 3],
    /// Unit normal (zero where there is none).
    pub n: [f32; 3],
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: ply_rs_bw::ply::Property) {
        if let ply_rs_bw::ply::Property::Float(v) = property {
            match name {
                "x" => self.x[0] = v,
                "y" => self.x[1] = v,
                "z" => self.x[2] = v,
                "nx" => self.n[0] = v,
                "ny" => self.n[1] = v,
                "nz" => self.n[2] = v,
                _ => {}
            }
        }
    }

    fn get_float(&self, name: &str) -> Option<f32> {
        match name {
            "x" => Some(self.x[0]),
            "y" => Some(self.x[1]),
            "z" => Some(self.x[2]),
            "nx" => Some(self.n[0]),
            "ny" => Some(self.n[1]),
            "nz" => Some(self.n[2]),
            _ => None,
        }
    }
}

/// A face as the PLY writer reads it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlyFace {
    /// Its corners' vertex indices.
    pub vertex_indices: Vec<i32>,
    /// Its corners' texture coordinates, `u v` each (empty when it has none).
    pub texcoord: Vec<f32>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: ply_rs_bw::ply::Property) {
        match (name, property) {
            ("vertex_indices", ply_rs_bw::ply::Property::ListInt(v)) => self.vertex_indices = v,
            ("texcoord", ply_rs_bw::ply::Property::ListFloat(v)) => self.texcoord = v,
            _ => {}
        }
    }

    fn get_list_int(&self, name: &str) -> Option<&[i32]> {
        (name == "vertex_indices").then_some(self.vertex_indices.as_slice())
    }

    fn get_list_float(&self, name: &str) -> Option<&[f32]> {
        (name == "texcoord").then_some(self.texcoord.as_slice())
    }
}

/// Writes a scene's frames as PLY files into one folder.
pub struct PlyExport {
    dir: PathBuf,
    /// The folder, held for this run.
    _lock: crate::output::lock::FolderLock,
    /// Every body's faces, as indices into the file's vertices.
    faces: Vec<PlyFace>,
    /// Whether some face has texture coordinates (then every face has the property).
    textured: bool,
    /// The faces as triangles, for the normals.
    triangles: Vec<[u32; 3]>,
    /// Buffers reused from frame to frame.
    normals: Vec<Vec3>,
    points: Vec<Vec3>,
    body_points: Vec<Vec3>,
    vertices: Vec<PlyVertex>,
    frames: u64,
}

impl PlyExport {
    /// Prepares the folder `dir` (created if missing; refused if it is a file, cleared of
    /// an earlier run's frames) for `scene`.
    pub fn new(dir: &Path, scene: &Scene) -> Result<Self> {
        let lock = super::frame_folder(dir, "ply")?;
        let mut faces = Vec::new();
        let mut triangles = Vec::new();
        let mut textured = false;
        let mut base = 0u32;
        for body in &scene.bodies {
            let uvs = body.skin.as_ref().map_or(&[][..], |s| &s.uvs[..]);
            let corner_uvs = |k: usize| -> Vec<f32> {
                body.skin
                    .as_ref()
                    .and_then(|s| s.faces[k].uvs.as_ref())
                    .map_or_else(Vec::new, |t| {
                        t.iter()
                            .flat_map(|&i| uvs[i as usize].map(|c| c as f32))
                            .collect()
                    })
            };
            for (k, f) in body.faces().into_iter().enumerate() {
                let texcoord = corner_uvs(k);
                textured |= !texcoord.is_empty();
                faces.push(PlyFace {
                    vertex_indices: f.iter().map(|&i| (i + base) as i32).collect(),
                    texcoord,
                });
            }
            triangles.extend(
                body.face_triangles()
                    .into_iter()
                    .map(|t| t.map(|i| i + base)),
            );
            base += body.vertex_count() as u32;
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            _lock: lock,
            faces,
            textured,
            triangles,
            normals: Vec::new(),
            points: Vec::new(),
            body_points: Vec::new(),
            vertices: Vec::new(),
            frames: 0,
        })
    }

    /// The file of frame `frame`.
    pub fn path(&self, frame: u64) -> PathBuf {
        self.dir.join(crate::output::frame_name(frame, "ply"))
    }

    fn write(
        &self,
        out: &mut impl std::io::Write,
        frame: u64,
        scene: &Scene,
    ) -> std::io::Result<()> {
        let mut header = Header::new();
        header.encoding = Encoding::BinaryLittleEndian;
        header.comments.push(format!(
            "hooke: scene {}, frame {frame}, t = {} s, metres, +Y up",
            scene.spec.name,
            Num(scene.simulation.time())
        ));
        let mut vertex = ElementDef::new("vertex".to_string());
        vertex.count = self.vertices.len();
        for name in ["x", "y", "z", "nx", "ny", "nz"] {
            let float = PropertyType::Scalar(ScalarType::Float);
            vertex
                .properties
                .add(PropertyDef::new(name.to_string(), float));
        }
        let mut face = ElementDef::new("face".to_string());
        face.count = self.faces.len();
        let list = PropertyType::List(ScalarType::UChar, ScalarType::Int);
        face.properties
            .add(PropertyDef::new("vertex_indices".to_string(), list));
        if self.textured {
            let list = PropertyType::List(ScalarType::UChar, ScalarType::Float);
            face.properties
                .add(PropertyDef::new("texcoord".to_string(), list));
        }
        header.elements.add(vertex.clone());
        header.elements.add(face.clone());
        Writer::<PlyVertex>::new().write_header(out, &header)?;
        Writer::<PlyVertex>::new().write_payload_of_element(
            out,
            &self.vertices,
            &vertex,
            &header,
        )?;
        Writer::<PlyFace>::new().write_payload_of_element(out, &self.faces, &face, &header)?;
        Ok(())
    }
}

impl crate::Sink for PlyExport {
    /// Writes frame `frame` of `scene` at its current state.
    fn frame(&mut self, frame: u64, scene: &Scene) -> Result<()> {
        let x = &scene.simulation.particles().x;
        self.points.clear();
        for body in &scene.bodies {
            body.vertices(x, &mut self.body_points);
            self.points.extend_from_slice(&self.body_points);
        }
        super::vertex_normals(&self.points, &self.triangles, &mut self.normals);
        self.vertices.clear();
        self.vertices.extend(
            self.points
                .iter()
                .zip(&self.normals)
                .map(|(p, n)| PlyVertex {
                    x: super::f32s(p),
                    n: super::f32s(n),
                }),
        );
        let path = self.path(frame);
        let mut file = OutputFile::create_named(&path, "--export")?;
        self.write(file.writer(), frame, scene)
            .with_context(|| format!("cannot write {}", path.display()))?;
        file.commit()?;
        crate::output::record_frame(&path, "--export")?;
        self.frames += 1;
        Ok(())
    }

    /// What was written, for the run's report.
    fn finish(self: Box<Self>) -> Result<String> {
        Ok(super::frames_written("PLY", self.frames, &self.dir))
    }
}
