//! What a render is asked for: size, supersampling, background.

use crate::draw_list::Rgb;

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Samples per pixel along each axis: 2 is 4× supersampling (the default for stills).
    pub supersample: u32,
    /// Background at the top and bottom of the image.
    pub background: [Rgb; 2],
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 800,
            height: 600,
            supersample: 2,
            background: [[0.80, 0.86, 0.93], [0.97, 0.97, 0.98]],
        }
    }
}
