//! Writes the shipped meshes (two tables and a ball): `cargo run -p hooke-collide --example gen_tables -- assets/meshes`.

use std::path::PathBuf;

fn main() -> std::io::Result<()> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "assets/meshes".into()),
    );
    std::fs::create_dir_all(&dir)?;
    for (name, text) in [
        ("table.obj", hooke_collide::table::round_table_obj()),
        ("square-table.obj", hooke_collide::table::square_table_obj()),
        ("ball.obj", hooke_collide::table::ball_obj()),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
