//! Image goldens: a still of each built-in scene and of one jello world, rendered and
//! compared with `golden/<name>.png` as decoded pixels.
//!
//! **Tolerance** (`hooke::report::pixels`, which `hooke report` uses too). A pixel matches
//! when each channel is within [`CHANNEL_TOLERANCE`] levels; an image matches when at most
//! `MISMATCH_FRACTION` of its pixels do not. Other platforms'
//! libm (sin/cos place the rotated jelly) and the sticking decisions of `cloth-table` (a
//! discontinuous response that amplifies round-off) may move a few edge pixels; a change to
//! the physics or the renderer moves whole surfaces, thousands of pixels.
//!
//! **Updating**, following insta's habits: by default a mismatch (or a missing golden)
//! writes `golden/<name>.new.png` and `target/golden-diff/<name>.diff.png` (mismatched
//! pixels red over the golden, dimmed) and fails; look at them, then accept by renaming the
//! `.new.png` over the golden or by running with `INSTA_UPDATE=always`, which overwrites
//! goldens. With `CI` set (or `INSTA_UPDATE=no`) nothing is written, only compared.

use crate::common::root;
use hooke::image_out::View;
use hooke::report::pixels::{CHANNEL_TOLERANCE, allowed, compare};
use hooke::stills::{still_scene, still_view};
use hooke_scene::Overrides;
use image::{Rgba, RgbaImage};
use std::path::{Path, PathBuf};

/// Golden stills are small: enough to recognise each scene, cheap to store and compare.
fn view() -> View {
    View {
        size: (320, 240),
        ..View::default()
    }
}

enum Update {
    /// Compare only (CI, or `INSTA_UPDATE=no`).
    Never,
    /// Write `.new.png` and a diff on mismatch (the default off CI).
    New,
    /// Overwrite the golden (`INSTA_UPDATE=always`).
    Always,
}

fn update_mode() -> Update {
    match std::env::var("INSTA_UPDATE").as_deref() {
        Ok("always") => Update::Always,
        Ok("no") => Update::Never,
        _ if std::env::var_os("CI").is_some() => Update::Never,
        _ => Update::New,
    }
}

fn save(path: &Path, image: &RgbaImage) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    image.save(path).unwrap();
}

/// Compares `actual` with `golden/<name>.png`, returning a failure message.
fn check(name: &str, actual: &RgbaImage) -> Option<String> {
    let golden_path = root().join("golden").join(format!("{name}.png"));
    let new_path = root().join("golden").join(format!("{name}.new.png"));
    let diff_path: PathBuf = root()
        .join("target/golden-diff")
        .join(format!("{name}.diff.png"));
    let mode = update_mode();
    if let Update::Always = mode {
        save(&golden_path, actual);
        return None;
    }
    // A golden that cannot be compared: keep the new image for review (off CI) and fail.
    let unusable = |message: String| {
        if let Update::New = mode {
            save(&new_path, actual);
        }
        Some(format!(
            "{message}; the new still is {}",
            new_path.display()
        ))
    };
    let golden = match image::open(&golden_path) {
        Ok(g) => g.to_rgba8(),
        Err(e) => {
            return unusable(format!(
                "{name}: no golden at {} ({e})",
                golden_path.display()
            ));
        }
    };
    if golden.dimensions() != actual.dimensions() {
        return unusable(format!(
            "{name}: golden is {:?} pixels, the still is {:?}",
            golden.dimensions(),
            actual.dimensions()
        ));
    }
    let (bad, diff) = compare(&golden, actual);
    let allowed = allowed((golden.width() * golden.height()) as usize);
    if bad <= allowed {
        let _ = std::fs::remove_file(&new_path);
        return None;
    }
    let written = if let Update::New = mode {
        save(&new_path, actual);
        save(&diff_path, &diff);
        format!(
            "actual: {}\n  diff:   {}",
            new_path.display(),
            diff_path.display()
        )
    } else {
        "(CI: nothing written)".to_string()
    };
    Some(format!(
        "{name}: {bad} pixels differ by more than {CHANNEL_TOLERANCE} levels (at most {allowed} may)\n  {written}"
    ))
}

#[test]
fn stills_match_the_golden_images() {
    let mut failures = Vec::new();
    for (name, _) in hooke_scene::builtin::BUILTINS {
        let scene = still_scene(name).unwrap();
        let view = still_view(name, &view());
        let image = view.pixels(&scene, &view.camera(&scene));
        failures.extend(check(name, &image));
    }
    // A jello world drawn as springs: box edges, the inclined plane and the three families.
    let world = root().join("assets/worlds/rotate.w");
    let mut scene = hooke::source::build(world.to_str().unwrap(), &Overrides::default()).unwrap();
    let steps = scene.steps;
    scene.simulation.advance(steps).unwrap();
    let springs = View {
        style: hooke::draw::Style::Springs,
        ..view()
    };
    let image = springs.pixels(&scene, &springs.camera(&scene));
    failures.extend(check("world-rotate", &image));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The comparison itself: identical images match, a moved square does not.
#[test]
fn the_comparison_catches_a_moved_surface_and_forgives_a_shade() {
    let square = |x0: u32, shade: u8| {
        RgbaImage::from_fn(100, 100, |x, y| {
            if (x0..x0 + 30).contains(&x) && (30..60).contains(&y) {
                Rgba([200, 40, 40, 255])
            } else {
                Rgba([shade, shade, shade, 255])
            }
        })
    };
    let golden = square(30, 230);
    assert_eq!(compare(&golden, &square(30, 230)).0, 0);
    // A background three levels off is within tolerance.
    assert_eq!(compare(&golden, &square(30, 227)).0, 0);
    // Moving the square 4 pixels changes 2 × 4 × 30 = 240 pixels: 2.4 %, far over 0.5 %.
    assert_eq!(compare(&golden, &square(34, 230)).0, 240);
}
