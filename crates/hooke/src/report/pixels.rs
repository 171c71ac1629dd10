//! A rendered still against its golden image, as decoded pixels: the comparison the
//! report and the validation suite's goldens both make.
//!
//! A pixel matches when each colour channel is within [`CHANNEL_TOLERANCE`] levels; an
//! image matches when at most [`MISMATCH_FRACTION`] of its pixels do not. Other platforms'
//! libm and the sticking decisions of a cloth may move a few edge pixels; a change to the
//! physics or the renderer moves whole surfaces, thousands of pixels.

use image::{Rgba, RgbaImage};

/// Channel difference (of 255) still counted as equal.
pub const CHANNEL_TOLERANCE: u8 = 4;
/// Fraction of pixels allowed to differ by more than [`CHANNEL_TOLERANCE`].
pub const MISMATCH_FRACTION: f64 = 0.005;

/// How many of `pixels` pixels may differ.
pub fn allowed(pixels: usize) -> usize {
    (MISMATCH_FRACTION * pixels as f64) as usize
}

/// Pixels of `actual` differing from `golden` by more than the tolerance, and a picture
/// of where: red over the golden in grey.
pub fn compare(golden: &RgbaImage, actual: &RgbaImage) -> (usize, RgbaImage) {
    let mut diff = RgbaImage::new(golden.width(), golden.height());
    let mut bad = 0;
    for ((g, a), d) in golden.pixels().zip(actual.pixels()).zip(diff.pixels_mut()) {
        let differs = g.0[..3]
            .iter()
            .zip(&a.0[..3])
            .any(|(g, a)| g.abs_diff(*a) > CHANNEL_TOLERANCE);
        *d = if differs {
            bad += 1;
            Rgba([255, 0, 0, 255])
        } else {
            let grey = (g.0[0] as u16 + g.0[1] as u16 + g.0[2] as u16) / 6 + 100;
            Rgba([grey as u8, grey as u8, grey as u8, 255])
        };
    }
    (bad, diff)
}
