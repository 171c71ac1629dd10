//! `hooke render`'s argument-to-picture path: arbitrary arguments (whitespace-separated
//! words) after a built-in scene name. Each is refused with an error or gives a picture of
//! the asked size; nothing panics.
#![no_main]

use libfuzzer_sys::fuzz_target;

/// Small built-ins, so that a fuzz run draws many pictures.
const SCENES: [&str; 3] = ["single-spring", "chain", "jello-cube"];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let mut args = vec![SCENES[pick as usize % SCENES.len()].to_string()];
    args.extend(text.split_whitespace().map(str::to_string));
    // Keep pictures small enough for many runs per second: the size parser itself is
    // exercised by the other words.
    if !args.iter().any(|a| a == "--size") {
        args.extend(["--size".to_string(), "64x48".to_string()]);
    }
    if let Ok(image) = hooke_cli::args::picture_from_args(&args, 200) {
        let size = args
            .iter()
            .rposition(|a| a == "--size")
            .and_then(|i| args.get(i + 1))
            .and_then(|s| hooke_cli::args::parse_size(s).ok());
        if let Some((w, h)) = size {
            assert_eq!(image.dimensions(), (w, h));
        }
    }
});
