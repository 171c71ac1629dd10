//! OBJ text from arbitrary bytes: parse and place it, then build a collider from it, both as
//! a solid (closed parts required) and as sheets; every failure must be an error.
#![no_main]

use hooke_collide::{Placement, TriMeshCollider, parse_obj};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("fuzz.obj");
    let Ok(parts) = parse_obj(text, path, &Placement::default()) else {
        return;
    };
    for solid in [true, false] {
        let _ = TriMeshCollider::new(String::from("fuzz"), parts.clone(), path, solid);
    }
});
