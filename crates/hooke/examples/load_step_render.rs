//! Load a scene with overrides, step it, read its state and render a still: what the
//! first Python example of docs/python.md does with `hooke.load`, `advance`, `positions`, `render`.
//!
//!     cargo run --release --example load_step_render -- [SCENE] [OUT.png]

use hooke::image_out::{View, write_png};
use hooke::scene::Overrides;
use std::path::PathBuf;

fn main() -> Result<(), hooke::Error> {
    let mut args = std::env::args().skip(1);
    let source = args.next().unwrap_or_else(|| "cloth-table".into());
    let out = PathBuf::from(args.next().unwrap_or_else(|| "still.png".into()));
    // A built-in name, a .toml scene or a .w world, with the command line's overrides.
    let overrides = Overrides {
        integrator: Some(hooke::core::Integrator::Rk4),
        dt: Some(1e-4),
        ..Overrides::default()
    };
    let mut scene = hooke::source::build(&source, &overrides)?;
    let steps = hooke::driver::steps_for(&scene, 1.0);
    hooke::driver::advance(&mut scene, steps)?;
    let x = &scene.simulation.particles().x;
    let lowest = x.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    println!(
        "{source}: t = {} s, {} particles, lowest at {lowest:.4} m",
        scene.simulation.time(),
        x.len()
    );
    let view = View {
        size: (800, 600),
        ..View::default()
    };
    write_png(&out, &view.pixels(&scene, &view.camera(&scene)))?;
    println!("still: {}", out.display());
    Ok(())
}
