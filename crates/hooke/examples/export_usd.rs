//! Export the rest of a run, as `Simulation.export(path)` does in Python and
//! `hooke run --export` on the command line: the format from the path (`.usda`, `.pc2`, or
//! a folder with PLY or OBJ frames), written through the library's one `Sink` interface,
//! never over the scene's own input files.
//!
//!     cargo run --release --example export_usd -- [SCENE] [OUT.usda]

use hooke::export::Target;
use hooke::output::claims::Claims;
use hooke::scene::Overrides;
use std::path::PathBuf;

fn main() -> Result<(), hooke::Error> {
    let mut args = std::env::args().skip(1);
    let source = args.next().unwrap_or_else(|| "cloth-table".into());
    let out = PathBuf::from(args.next().unwrap_or_else(|| "cloth.usda".into()));
    let read = hooke::source::read(&source)?;
    let overrides = Overrides {
        duration: Some(1.0),
        ..Overrides::default()
    };
    let prepared = hooke::source::prepare(read, &source, &overrides)?;
    let target = Target::new(&out, None, None)?;
    // No output may replace a file the scene is built from.
    let mut claims = Claims::with_inputs(prepared.inputs());
    target.claim(&mut claims);
    claims.check()?;
    let mut scene = hooke::source::build_prepared(prepared, &source)?;
    let sink = hooke::export::create(&target, &scene)?;
    let recording = hooke::record(&mut scene, vec![sink], |_, _| Ok(()))?;
    if let Some(stopped) = recording.stopped {
        eprintln!("stopped early, the export ends at the last whole frame: {stopped}");
    }
    for written in recording.written {
        println!("export: {written}");
    }
    Ok(())
}
