//! A colour map's legend, drawn over a rendered image as ParaView and matplotlib draw
//! theirs: a vertical bar at the right edge with the quantity's name and unit above it and
//! the range's ends (and middle) beside it, in the 8×8 public-domain font on a light panel.

use crate::colormap::ColorMap;
use font8x8::UnicodeFonts;

/// What a legend shows.
#[derive(Clone, Debug, PartialEq)]
pub struct Legend {
    /// The map the surface was coloured with.
    pub map: ColorMap,
    /// The values at the map's ends, in the unit of `title`: `range.0` at the bottom.
    pub range: (f64, f64),
    /// The quantity and its unit, e.g. `strain (%)`.
    pub title: String,
    /// A value to mark on the bar with its label, e.g. a contact thickness.
    pub mark: Option<(f64, String)>,
}

/// `v` in at most 4 significant digits, without float noise: `0.0125`, `-3.2`, `1.5e-5`.
pub fn short(v: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        let s = format!("{v:.digits$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        if s == "-0" { "0".to_string() } else { s }
    } else {
        format!("{v:.2e}")
    }
}

impl Legend {
    /// The labels at the bar's top and bottom: the range's ends as printed.
    pub fn end_labels(&self) -> (String, String) {
        (short(self.range.1), short(self.range.0))
    }

    /// Where the bar is in an image of `width × height`: `(x0, y0, x1, y1)`, pixels, the
    /// top row the map's high end.
    pub fn bar(&self, width: u32, height: u32) -> (u32, u32, u32, u32) {
        let scale = text_scale(height);
        let x1 = width.saturating_sub(12 * scale + 8 * 9 * scale);
        let x0 = x1.saturating_sub(6 * scale);
        let y0 = (height as f64 * 0.18) as u32 + 12 * scale;
        let y1 = (height as f64 * 0.82) as u32;
        (x0, y0, x1, y1.max(y0 + 2))
    }

    /// Draws the legend over `pixels` (RGBA8, row-major, `width × height`).
    pub fn draw(&self, pixels: &mut [u8], width: u32, height: u32) {
        if width < 64 || height < 48 || pixels.len() < (width * height * 4) as usize {
            return;
        }
        let scale = text_scale(height);
        let (x0, y0, x1, y1) = self.bar(width, height);
        let glyph = 8 * scale;
        // A light panel behind bar and labels, so they read on any scene.
        let title_width = self.title.chars().count() as u32 * glyph;
        let panel_x0 = x0
            .saturating_sub(4 * scale)
            .min(width.saturating_sub(title_width + 8 * scale));
        let panel = (
            panel_x0,
            y0.saturating_sub(glyph + 10 * scale),
            width - 2,
            y1 + glyph,
        );
        blend_rect(pixels, width, panel, [255, 255, 255], 0.75);
        let (lo, hi) = self.range;
        for y in y0..y1 {
            let t = 1.0 - (y - y0) as f64 / (y1 - y0 - 1).max(1) as f64;
            let c = self
                .map
                .at(t)
                .map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
            for x in x0..x1 {
                put(pixels, width, x, y, c);
            }
        }
        let dark = [30, 30, 36];
        let label_x = x1 + 3 * scale;
        let (top, bottom) = self.end_labels();
        text(
            pixels,
            (width, height),
            (label_x, y0.saturating_sub(glyph / 2)),
            &top,
            scale,
            dark,
        );
        text(
            pixels,
            (width, height),
            (label_x, y1.saturating_sub(glyph / 2)),
            &bottom,
            scale,
            dark,
        );
        let mid = 0.5 * (lo + hi);
        let ym = (y0 + y1) / 2;
        text(
            pixels,
            (width, height),
            (label_x, ym.saturating_sub(glyph / 2)),
            &short(mid),
            scale,
            dark,
        );
        text(
            pixels,
            (width, height),
            (panel.0 + 2 * scale, y0.saturating_sub(glyph + 6 * scale)),
            &self.title,
            scale,
            dark,
        );
        if let Some((value, label)) = &self.mark
            && hi > lo
            && (lo..=hi).contains(value)
        {
            let t = (value - lo) / (hi - lo);
            let y = y1 - 1 - ((y1 - y0 - 1) as f64 * t).round() as u32;
            for x in x0.saturating_sub(2 * scale)..x1 + 2 * scale {
                for dy in 0..scale {
                    put(pixels, width, x, y + dy, dark);
                }
            }
            let left = (label.chars().count() as u32 + 1) * glyph;
            text(
                pixels,
                (width, height),
                (x0.saturating_sub(left), y.saturating_sub(glyph / 2)),
                label,
                scale,
                dark,
            );
        }
    }
}

/// The font's scale: 1 up to 600 pixels high, 2 above.
fn text_scale(height: u32) -> u32 {
    if height > 600 { 2 } else { 1 }
}

fn put(pixels: &mut [u8], width: u32, x: u32, y: u32, c: [u8; 3]) {
    let k = ((y * width + x) * 4) as usize;
    if let Some(p) = pixels.get_mut(k..k + 3) {
        p.copy_from_slice(&c);
    }
}

/// `c` over the rectangle `(x0, y0, x1, y1)` with opacity `alpha`.
fn blend_rect(
    pixels: &mut [u8],
    width: u32,
    (x0, y0, x1, y1): (u32, u32, u32, u32),
    c: [u8; 3],
    alpha: f32,
) {
    let height = pixels.len() as u32 / 4 / width.max(1);
    for y in y0..y1.min(height) {
        for x in x0..x1.min(width) {
            let k = ((y * width + x) * 4) as usize;
            for (ch, &v) in c.iter().enumerate() {
                let old = pixels[k + ch] as f32;
                pixels[k + ch] = (old * (1.0 - alpha) + v as f32 * alpha + 0.5) as u8;
            }
        }
    }
}

/// Writes `s` with its top left at `(x, y)`, each font pixel `scale × scale`.
fn text(
    pixels: &mut [u8],
    (width, height): (u32, u32),
    (x, y): (u32, u32),
    s: &str,
    scale: u32,
    c: [u8; 3],
) {
    for (k, ch) in s.chars().enumerate() {
        let Some(glyph) = font8x8::BASIC_FONTS.get(ch) else {
            continue;
        };
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8u32 {
                if bits >> col & 1 == 0 {
                    continue;
                }
                for sy in 0..scale {
                    for sx in 0..scale {
                        let px = x + (k as u32 * 8 + col) * scale + sx;
                        let py = y + row as u32 * scale + sy;
                        if px < width && py < height {
                            put(pixels, width, px, py, c);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_short_and_without_noise() {
        assert_eq!(short(0.1 + 0.2), "0.3");
        assert_eq!(short(12.5), "12.5");
        assert_eq!(short(-0.0125), "-0.0125");
        assert_eq!(short(0.0), "0");
        assert_eq!(short(1.5e-5), "1.50e-5");
        assert_eq!(short(123456.0), "1.23e5");
    }

    #[test]
    fn the_bar_runs_from_the_maps_high_end_at_the_top_to_its_low_end() {
        let legend = Legend {
            map: ColorMap::Viridis,
            range: (0.0, 2.0),
            title: "speed (m/s)".into(),
            mark: None,
        };
        let (w, h) = (320, 240);
        let mut pixels = vec![255u8; (w * h * 4) as usize];
        legend.draw(&mut pixels, w, h);
        let (x0, y0, _, y1) = legend.bar(w, h);
        let at = |y: u32| {
            let k = ((y * w + x0 + 1) * 4) as usize;
            [pixels[k], pixels[k + 1], pixels[k + 2]]
        };
        let expect = |t: f64| ColorMap::Viridis.at(t).map(|v| (v * 255.0 + 0.5) as u8);
        assert_eq!(at(y0), expect(1.0));
        assert_eq!(at(y1 - 1), expect(0.0));
        assert_eq!(legend.end_labels(), ("2".to_string(), "0".to_string()));
    }
}
