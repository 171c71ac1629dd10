//! A run drawn frame by frame: numbered PNGs in a folder and a GIF, each written as the
//! frame comes.

use crate::error::Result;
use crate::image_out::{GifWriter, View, write_png_named};
use crate::output::{frame_name, prepare_frame_folder};
use crate::quantity::ColorBy;
use hooke_scene::Scene;
use std::path::PathBuf;

/// The range an animation of `scene` shows quantity `by` with, so that its colours compare
/// from frame to frame: a first pass runs the scene to its end (it is deterministic: the
/// second pass is the same run) and takes the largest magnitude over its frames, rounded
/// up as a still's is ([`ColorBy::default_range`]). A run that stops early (diverges, or
/// is interrupted) gives the range of the frames it reached.
pub fn animation_range(mut scene: Scene, by: ColorBy) -> (f64, f64) {
    let every = scene.every.max(1);
    let largest = |scene: &Scene| {
        by.values(scene)
            .unwrap_or_default()
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let mut top = largest(&scene);
    let mut done = 0;
    while done < scene.steps {
        let n = every.min(scene.steps - done);
        if crate::driver::advance(&mut scene, n).is_err() {
            break;
        }
        done += n;
        top = top.max(largest(&scene));
    }
    by.default_range(&scene, &[top])
}

/// Writes frames of a run as numbered PNGs and optionally a GIF, each as it comes.
pub struct Frames {
    dir: Option<PathBuf>,
    /// The frame folder, held for this run.
    _lock: Option<crate::output::lock::FolderLock>,
    gif: Option<GifWriter>,
    view: View,
    camera: Option<hooke_render::Camera>,
}

impl Frames {
    /// Prepares the outputs before a run (whose paths `run` has checked before building the
    /// scene): the frame folder is created and cleared of an earlier run's frames, the GIF
    /// started.
    pub fn new(
        dir: Option<PathBuf>,
        gif: Option<PathBuf>,
        view: View,
        frame_seconds: f64,
    ) -> Result<Option<Self>> {
        if dir.is_none() && gif.is_none() {
            return Ok(None);
        }
        let mut lock = None;
        if let Some(d) = &dir {
            let (held, removed) = prepare_frame_folder(d, "--frames", "png")?;
            lock = Some(held);
            if removed > 0 {
                eprintln!(
                    "--frames: removed {removed} frame{} of an earlier run from {}",
                    if removed == 1 { "" } else { "s" },
                    d.display()
                );
            }
        }
        let gif = match &gif {
            Some(path) => Some(GifWriter::create(path, view.size, frame_seconds * 1000.0)?),
            None => None,
        };
        Ok(Some(Self {
            dir,
            _lock: lock,
            gif,
            view,
            camera: None,
        }))
    }
}

impl crate::Sink for Frames {
    /// Draws one frame; the camera is fixed by the first frame, with room for motion.
    fn frame(&mut self, frame: u64, scene: &Scene) -> Result<()> {
        let camera = *self.camera.get_or_insert_with(|| {
            let mut c = self.view.camera(scene);
            c.distance *= 1.3;
            c
        });
        let image = self.view.pixels(scene, &camera);
        if let Some(d) = &self.dir {
            let path = d.join(frame_name(frame, "png"));
            write_png_named(&path, "--frames", &image)?;
            crate::output::record_frame(&path, "--frames")?;
        }
        if let Some(g) = self.gif.as_mut() {
            g.frame(image)?;
        }
        Ok(())
    }

    /// Puts the GIF in place.
    fn finish(self: Box<Self>) -> Result<String> {
        let mut written = Vec::new();
        if let Some(d) = &self.dir {
            written.push(format!("frames: {}", d.display()));
        }
        if let Some(g) = self.gif {
            written.push(format!("gif: {}", g.path().display()));
            g.finish()?;
        }
        Ok(written.join(", "))
    }
}
