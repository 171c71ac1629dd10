//! Telling failures apart, as the Python package's `HookeError` and `DivergenceError` do:
//! `hooke::Error`'s variants say whether the input was bad (and where), the simulation
//! diverged, an output was refused or the run was interrupted.
//!
//!     cargo run --release --example errors

use hooke::Error;
use hooke::scene::Overrides;

fn main() {
    // A scene file with a typo on its third line.
    let dir = std::env::temp_dir().join(format!("hooke-example-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "name = \"bad\"\n[simulation]\ndt = \"fast\"\n").expect("a file");
    match hooke::source::build(bad.to_str().unwrap(), &Overrides::default()) {
        Err(Error::Input { location, message }) => {
            println!(
                "bad input at {:?} line {:?}:\n  {message}",
                location.file, location.line
            )
        }
        other => println!("unexpected: {:?}", other.err()),
    }
    // Springs far too stiff for explicit Euler at this step: it diverges.
    let overrides = Overrides {
        integrator: Some(hooke::core::Integrator::Euler),
        dt: Some(0.05),
        ..Overrides::default()
    };
    let mut scene = hooke::source::build("chain", &overrides).expect("the built-in chain");
    let steps = scene.steps;
    match hooke::driver::advance(&mut scene, steps) {
        Err(Error::Diverged { divergence, .. }) => println!("diverged: {divergence}"),
        other => println!("unexpected: {other:?}"),
    }
    // Refusing to write a picture over a folder.
    match hooke::output::check_output_file(&dir, "-o", &["png"]) {
        Err(e @ Error::Output { .. }) => println!("refused output: {e}"),
        other => println!("unexpected: {:?}", other.err()),
    }
    std::fs::remove_dir_all(&dir).ok();
}
