//! `hooke convert`: a `.w` world to a TOML scene and back.

use anyhow::{Context, Result, bail};
use hooke::output::check_output_file;
use hooke::output::claims::Claims;
use std::path::Path;
use std::process::ExitCode;

pub fn convert(input: &Path, output: &Path) -> Result<ExitCode> {
    let streamed = check_output_file(output, "convert", &["toml", "w"])?.is_stream();
    let mut claims = Claims::default();
    claims.input("the file converted", input);
    claims.file("convert", output);
    claims.check()?;
    let ext = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_string()
    };
    // A stream (`-`, a device, a FIFO) takes the other format than the input's.
    let to = match (streamed, ext(input).as_str()) {
        (true, "w") => "toml".to_string(),
        (true, "toml") => "w".to_string(),
        _ => ext(output),
    };
    let text = match (ext(input).as_str(), to.as_str()) {
        ("w", "toml") => {
            let world = hooke_scene::world::load_world(input)?;
            let name = input
                .file_stem()
                .map_or("world".into(), |s| s.to_string_lossy().into_owned());
            let spec = world
                .to_scene(&name)
                .with_context(|| format!("{}", input.display()))?;
            hooke_scene::to_toml(&spec)
        }
        ("toml", "w") => {
            let spec = hooke_scene::load_scene(input)?;
            let world = hooke_scene::world::World::from_scene(&spec)
                .with_context(|| format!("{} cannot be saved as a jello world", input.display()))?;
            world.to_text()
        }
        (a, b) => bail!(
            "cannot convert .{a} to .{b}: expected a .w world and a .toml scene, one each way"
        ),
    };
    crate::output::write_atomic(output, text.as_bytes())?;
    eprintln!("wrote {}", output.display());
    Ok(ExitCode::SUCCESS)
}
