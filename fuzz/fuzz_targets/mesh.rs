//! OBJ text from arbitrary bytes as a body's mesh, read from a file the way `hooke run`
//! reads it (the same text reader, OBJ parser and body build): as a cloth (`kind = "mesh"`)
//! and as a jelly (`kind = "solid"`). Every failure must be an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

/// This process's mesh file (libFuzzer runs inputs one after another in a process).
fn file() -> PathBuf {
    std::env::temp_dir().join(format!("hooke-fuzz-mesh-{}.obj", std::process::id()))
}

fuzz_target!(|data: &[u8]| {
    let path = file();
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let quoted = format!("{:?}", path.display().to_string());
    for shape in [
        format!("{{ kind = \"mesh\", path = {quoted} }}"),
        format!("{{ kind = \"solid\", path = {quoted}, spacing = 0.05 }}"),
    ] {
        let text = format!(
            "name = \"fuzz\"\n[simulation]\nintegrator = \"symplectic\"\ndt = 0.001\nsteps = 1\n\
             every = 1\n[[body]]\nname = \"b\"\nshape = {shape}\nmaterial = {{ preset = \"cotton\" }}\n"
        );
        let spec =
            hooke_scene::parse_scene(&text, "fuzz.toml").expect("the scene around the mesh reads");
        // `hooke run` refuses a scene over its memory budget before building it; here the
        // budget is a fixed 256 MiB, so that a fuzz run builds many inputs a second.
        let footprint = spec.footprint(&std::env::temp_dir());
        if footprint.bytes() > 256 << 20 {
            continue;
        }
        let _ = spec.build(&std::env::temp_dir());
    }
});
