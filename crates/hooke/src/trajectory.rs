//! Trajectory CSV (docs/physics.md §6): `frame,time,particle,x,y,z,vx,vy,vz`, numbers in
//! their shortest round-trip form ([`hooke_core::Num`]: scientific far from 1).

use crate::error::{Context, Result};
use crate::output::OutputFile;
use hooke_core::{Num, Particles, Vec3};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The CSV header line.
pub const HEADER: &str = "frame,time,particle,x,y,z,vx,vy,vz";

/// A trajectory file being written frame by frame.
pub struct TrajectoryWriter {
    file: OutputFile,
    path: PathBuf,
}

impl TrajectoryWriter {
    /// Starts a trajectory file (in place only when finished).
    pub fn create(path: &Path) -> Result<Self> {
        let mut file = OutputFile::create(path)?;
        writeln!(file.writer(), "{HEADER}")
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(Self {
            file,
            path: path.to_path_buf(),
        })
    }

    /// Appends one frame of particles at `time` seconds.
    pub fn append(&mut self, frame: u64, time: f64, p: &Particles) -> Result<()> {
        for (i, (x, v)) in p.x.iter().zip(&p.v).enumerate() {
            self.row((frame, time, i), x, v)?;
        }
        Ok(())
    }
}

impl TrajectoryWriter {
    /// Appends one frame of the vertices `scene`'s bodies show at `time` seconds, body after
    /// body: a generated body's particles, a mesh body's file vertices in their count and
    /// order (docs/physics.md §6). Without mesh bodies these are the particles, in order.
    pub fn append_scene(
        &mut self,
        frame: u64,
        time: f64,
        scene: &hooke_scene::Scene,
    ) -> Result<()> {
        let p = scene.simulation.particles();
        if scene.bodies.iter().all(|b| b.skin.is_none()) {
            return self.append(frame, time, p);
        }
        let (mut x, mut v) = (Vec::new(), Vec::new());
        let mut row = 0usize;
        for body in &scene.bodies {
            body.vertices(&p.x, &mut x);
            body.vertex_velocities(&p.v, &mut v);
            for (x, v) in x.iter().zip(&v) {
                self.row((frame, time, row), x, v)?;
                row += 1;
            }
        }
        Ok(())
    }

    /// One row: frame, time, the row's index in the frame, position and velocity.
    fn row(&mut self, (frame, time, i): (u64, f64, usize), x: &Vec3, v: &Vec3) -> Result<()> {
        writeln!(
            self.file.writer(),
            "{frame},{},{i},{},{},{},{},{},{}",
            Num(time),
            Num(x.x),
            Num(x.y),
            Num(x.z),
            Num(v.x),
            Num(v.y),
            Num(v.z)
        )
        .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

impl crate::Sink for TrajectoryWriter {
    fn frame(&mut self, frame: u64, scene: &hooke_scene::Scene) -> Result<()> {
        let time = crate::driver::frame_time(scene, frame);
        self.append_scene(frame, time, scene)
    }

    /// Puts the file in place. Called after the last frame, and after a divergence too: the
    /// frames written before it are complete and stay.
    fn finish(self: Box<Self>) -> Result<String> {
        self.file.commit()?;
        Ok(format!("trajectory: {}", self.path.display()))
    }
}
