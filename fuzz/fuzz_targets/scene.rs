//! A TOML scene from arbitrary text: load it and, if it loads, build it (meshes are not read:
//! a `path` names a file that does not exist, which must be an error, not a panic).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(spec) = hooke_scene::parse_scene(text, "fuzz.toml") else {
        return;
    };
    // Building allocates the particles: skip scenes too large to build in a fuzz run.
    let _ = spec.build(Path::new("/nonexistent-fuzz-base"));
});
