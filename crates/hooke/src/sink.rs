//! One interface for everything a run writes frame by frame: the trajectory CSV, PNG frames
//! and GIFs, and the exports (USD, PC2, PLY, OBJ).

use crate::Result;
use hooke_scene::Scene;

/// An output written frame by frame as a scene runs. Nothing appears at its path before
/// [`Sink::finish`]; a sink dropped unfinished leaves nothing behind.
pub trait Sink {
    /// Writes frame `frame` (0 is the start): the scene at its current state.
    fn frame(&mut self, frame: u64, scene: &Scene) -> Result<()>;
    /// Puts the output in place with the frames written so far, and says what was written.
    fn finish(self: Box<Self>) -> Result<String>;
}

/// How a [`record`]ed run ended, when its outputs were kept.
pub struct Recording {
    /// `None` when the run reached its end; otherwise the divergence or interrupt that
    /// stopped it (the outputs end at the last complete frame).
    pub stopped: Option<crate::Error>,
    /// What each sink wrote, in the order given.
    pub written: Vec<String>,
}

/// Runs `scene` to its end through [`crate::driver::drive`], writing every frame to each of
/// `sinks` and then calling `also`. After a divergence or an interrupt the frames already
/// written are complete, so the outputs are finished and kept; any other error drops them
/// unfinished (nothing is left behind) and is returned.
pub fn record(
    scene: &mut Scene,
    mut sinks: Vec<Box<dyn Sink>>,
    mut also: impl FnMut(u64, &Scene) -> Result<()>,
) -> Result<Recording> {
    let result = crate::driver::drive(scene, |frame, scene| {
        for sink in sinks.iter_mut() {
            sink.frame(frame, scene)?;
        }
        also(frame, scene)
    });
    let stopped = match result {
        Ok(()) => None,
        Err(e @ (crate::Error::Diverged { .. } | crate::Error::Interrupted { .. })) => Some(e),
        Err(e) => return Err(e),
    };
    let written = sinks
        .into_iter()
        .map(|sink| sink.finish())
        .collect::<Result<_>>()?;
    Ok(Recording { stopped, written })
}
