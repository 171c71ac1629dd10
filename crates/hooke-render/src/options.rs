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
    /// Whether the key light casts shadows (from every triangle, onto every triangle).
    pub shadows: bool,
    /// The share of a surface's colour it shows unlit (the rest comes from the key light):
    /// 0.35 for pictures, more where the colours carry a quantity and must read on the
    /// side away from the light.
    pub ambient: f32,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 800,
            height: 600,
            supersample: 2,
            background: [[0.80, 0.86, 0.93], [0.97, 0.97, 0.98]],
            shadows: true,
            ambient: 0.35,
        }
    }
}
