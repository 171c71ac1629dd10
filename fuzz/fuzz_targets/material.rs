//! A material file (`hooke drape FILE.toml`) from arbitrary text: parsed through the same
//! function the drape test uses, and resolved into SI values as the drape and a scene's
//! `[body.material]` do. Every failure must be an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(spec) = hooke_scene::material::parse_material_file(text, Path::new("fuzz.toml")) else {
        return;
    };
    if let Ok(m) = spec.resolve("material") {
        // A resolved material is one a cloth can be made of.
        assert!(m.density > 0.0 && m.density.is_finite(), "{m:?}");
        let _ = m.masses([3, 3], 0.01);
    }
});
