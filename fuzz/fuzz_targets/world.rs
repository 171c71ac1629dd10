//! A `.w` world from arbitrary text: read it; if it reads, it must convert to a scene (whose
//! build may still refuse it with an error), and write back to text that reads the same.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("fuzz.w");
    let Ok(world) = hooke_scene::world::parse_world(text, path) else {
        return;
    };
    let again = hooke_scene::world::parse_world(&world.to_text(), path)
        .expect("a written world reads back");
    assert_eq!(again.to_text(), world.to_text());
    // The reader checks every value, so a world that reads converts to a scene.
    let scene = world
        .to_scene("fuzz")
        .expect("a world that reads converts to a scene");
    let _ = scene.build(Path::new("."));
});
