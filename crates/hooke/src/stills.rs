//! The demo's still of each built-in scene: when it is taken and from where. `hooke demo`
//! writes them; the validation suite compares them with the golden images.

use crate::error::Result;
use crate::image_out::View;
use crate::source;
use hooke_scene::{Overrides, Scene};

/// Scenes whose still is taken before the end of the run, and when (seconds): the jelly is
/// most telling at impact, squashed against the ground.
const STILL_AT: [(&str, f64); 1] = [("jello-cube", 0.45)];

/// The steps from the start of built-in scene `name` to the moment of its still.
pub fn still_steps(name: &str, scene: &Scene) -> u64 {
    match STILL_AT.iter().find(|(n, _)| *n == name) {
        Some((_, t)) => crate::driver::steps_for(scene, *t),
        None => scene.steps,
    }
}

/// Builds built-in scene `name` and runs it to the moment of its still.
pub fn still_scene(name: &str) -> Result<Scene> {
    let mut scene = source::build(name, &Overrides::default())?;
    let steps = still_steps(name, &scene);
    scene.steps = steps;
    crate::driver::advance(&mut scene, steps)?;
    Ok(scene)
}

/// The view of built-in scene `name`'s still, from the user's `view`.
pub fn still_view(name: &str, view: &View) -> View {
    // The cloth hangs in the y-z plane from its pins, the flag streams in the x-y plane:
    // look at their faces, not their edges.
    let turn = match name {
        "hanging-cloth" => 35.0,
        "flag" => -30.0,
        _ => 0.0,
    };
    View {
        yaw: view.yaw + turn,
        ..view.clone()
    }
}
