//! Writes the mesh bodies' example meshes: `cargo run -p hooke-scene --example gen_meshes -- assets/meshes`.

use std::path::PathBuf;

fn main() -> std::io::Result<()> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "assets/meshes".into()),
    );
    std::fs::create_dir_all(&dir)?;
    for (name, text) in hooke_scene::BUILTIN_MESHES.iter().filter(|(name, _)| {
        !["table.obj", "square-table.obj", "ball.obj"].contains(name) && !name.starts_with("drape-")
    }) {
        let path = dir.join(name);
        std::fs::write(&path, text())?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
