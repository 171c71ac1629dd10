//! `--export DIR/ --format ply`: one binary little-endian PLY per frame, written with the
//! `ply-rs-bw` crate (the maintained fork of `ply-rs`).
//!
//! `DIR/frame-00000.ply` holds frame 0, and so on: an element `vertex` per particle (vertex
//! `i` is particle `i`) with `x y z` and a unit normal `nx ny nz` (the area-weighted normal
//! of its triangles, zero off every surface), and an element `face` with the bodies'
//! triangles as `vertex_indices`. Colliders do not move and are left out (`--format obj`
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

/// A triangle as the PLY writer reads it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlyFace {
    /// Its corners' vertex indices.
    pub vertex_indices: Vec<i32>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: ply_rs_bw::ply::Property) {
        if let ("vertex_indices", ply_rs_bw::ply::Property::ListInt(v)) = (name, property) {
            self.vertex_indices = v;
        }
    }

    fn get_list_int(&self, name: &str) -> Option<&[i32]> {
        (name == "vertex_indices").then_some(self.vertex_indices.as_slice())
    }
}

/// Writes a scene's frames as PLY files into one folder.
pub struct PlyExport {
    dir: PathBuf,
    /// The folder, held for this run.
    _lock: crate::output::lock::FolderLock,
    /// The triangles of every body, as particle indices.
    faces: Vec<PlyFace>,
    triangles: Vec<[u32; 3]>,
    /// Buffers reused from frame to frame.
    normals: Vec<Vec3>,
    vertices: Vec<PlyVertex>,
    frames: u64,
}

impl PlyExport {
    /// Prepares the folder `dir` (created if missing; refused if it is a file, cleared of
    /// an earlier run's frames) for `scene`.
    pub fn new(dir: &Path, scene: &Scene) -> Result<Self> {
        let lock = super::frame_folder(dir, "ply")?;
        let triangles: Vec<[u32; 3]> = scene
            .bodies
            .iter()
            .flat_map(|b| b.triangles.iter().copied())
            .collect();
        let faces = triangles
            .iter()
            .map(|t| PlyFace {
                vertex_indices: t.iter().map(|&i| i as i32).collect(),
            })
            .collect();
        Ok(Self {
            dir: dir.to_path_buf(),
            _lock: lock,
            faces,
            triangles,
            normals: Vec::new(),
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
        super::vertex_normals(x, &self.triangles, &mut self.normals);
        self.vertices.clear();
        self.vertices
            .extend(x.iter().zip(&self.normals).map(|(p, n)| PlyVertex {
                x: super::f32s(p),
                n: super::f32s(n),
            }));
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
