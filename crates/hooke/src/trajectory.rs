//! Trajectory CSV (docs/physics.md §6): `frame,time,particle,x,y,z,vx,vy,vz`, numbers in
//! their shortest round-trip form ([`hooke_core::Num`]: scientific far from 1).

use crate::error::{Context, Result};
use crate::output::OutputFile;
use hooke_core::{Num, Particles};
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
        let w = self.file.writer();
        for (i, (x, v)) in p.x.iter().zip(&p.v).enumerate() {
            writeln!(
                w,
                "{frame},{},{i},{},{},{},{},{},{}",
                Num(time),
                Num(x.x),
                Num(x.y),
                Num(x.z),
                Num(v.x),
                Num(v.y),
                Num(v.z)
            )
            .with_context(|| format!("cannot write {}", self.path.display()))?;
        }
        Ok(())
    }
}

impl crate::Sink for TrajectoryWriter {
    fn frame(&mut self, frame: u64, scene: &hooke_scene::Scene) -> Result<()> {
        let time = crate::driver::frame_time(scene, frame);
        self.append(frame, time, scene.simulation.particles())
    }

    /// Puts the file in place. Called after the last frame, and after a divergence too: the
    /// frames written before it are complete and stay.
    fn finish(self: Box<Self>) -> Result<String> {
        self.file.commit()?;
        Ok(format!("trajectory: {}", self.path.display()))
    }
}
