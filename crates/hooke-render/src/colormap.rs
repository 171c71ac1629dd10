//! Colour maps for scalar quantities on a surface: viridis (sequential, perceptually
//! uniform; van der Walt & Smith, matplotlib 2015) and coolwarm (diverging, centred on its
//! middle; Moreland 2009), each as its published control points interpolated linearly.

use crate::draw_list::Rgb;

/// A colour map from `[0, 1]` to colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorMap {
    /// Sequential: dark blue-violet through teal to yellow. For magnitudes (speed, gap).
    Viridis,
    /// Diverging: blue through light grey (at ½) to red. For signed quantities centred on
    /// zero (strain).
    Coolwarm,
}

/// matplotlib's viridis at `k / 9`, `k = 0..=9` (#440154 … #FDE725).
const VIRIDIS: [[u8; 3]; 10] = [
    [0x44, 0x01, 0x54],
    [0x48, 0x28, 0x78],
    [0x3E, 0x4A, 0x89],
    [0x31, 0x68, 0x8E],
    [0x26, 0x82, 0x8E],
    [0x1F, 0x9E, 0x89],
    [0x35, 0xB7, 0x79],
    [0x6D, 0xCD, 0x59],
    [0xB4, 0xDE, 0x2C],
    [0xFD, 0xE7, 0x25],
];

/// Moreland's cool to warm at `k / 4`.
const COOLWARM: [[f32; 3]; 5] = [
    [0.230, 0.299, 0.754],
    [0.552, 0.690, 0.996],
    [0.865, 0.865, 0.865],
    [0.958, 0.604, 0.482],
    [0.706, 0.016, 0.150],
];

impl ColorMap {
    /// The colour at `t`, clamped to `[0, 1]` (NaN gives the low end).
    pub fn at(self, t: f64) -> Rgb {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let table: Vec<Rgb> = match self {
            Self::Viridis => VIRIDIS
                .iter()
                .map(|c| c.map(|v| v as f32 / 255.0))
                .collect(),
            Self::Coolwarm => COOLWARM.to_vec(),
        };
        let x = t * (table.len() - 1) as f64;
        let k = (x.floor() as usize).min(table.len() - 2);
        let f = (x - k as f64) as f32;
        [0, 1, 2].map(|c| table[k][c] * (1.0 - f) + table[k + 1][c] * f)
    }

    /// Its name: `viridis` or `coolwarm`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Viridis => "viridis",
            Self::Coolwarm => "coolwarm",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ends_and_middle_are_the_published_colours() {
        let close = |a: Rgb, b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6);
        assert!(close(
            ColorMap::Viridis.at(0.0),
            [0x44 as f32 / 255.0, 1.0 / 255.0, 0x54 as f32 / 255.0]
        ));
        assert!(close(
            ColorMap::Viridis.at(1.0),
            [
                0xFD as f32 / 255.0,
                0xE7 as f32 / 255.0,
                0x25 as f32 / 255.0
            ]
        ));
        assert!(close(ColorMap::Coolwarm.at(0.5), [0.865; 3]));
        assert!(close(ColorMap::Coolwarm.at(-3.0), COOLWARM[0]));
        assert!(close(ColorMap::Coolwarm.at(f64::NAN), COOLWARM[0]));
    }

    #[test]
    fn viridis_grows_lighter_from_end_to_end() {
        // Perceptual uniformity's first property: lightness (here luma) rises monotonically.
        let luma = |c: Rgb| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        let mut last = -1.0;
        for k in 0..=100 {
            let l = luma(ColorMap::Viridis.at(k as f64 / 100.0));
            assert!(l > last, "luma falls at {k}%");
            last = l;
        }
    }
}
