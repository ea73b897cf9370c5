//! Labelled side-by-side images for `lineao render --compare` and `--grid`: the split screen
//! with its divider, the grid of tiles, and text burned into sRGB pixels with the public-domain
//! 8 × 8 bitmap font of `font8x8`, scaled to the image (no font files, no rasterizer).

use anyhow::Result;

/// An sRGB image, 4 bytes per pixel, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Rgba8 {
    pub width: u32,
    pub height: u32,
    pub data: Vec<u8>,
}

impl Rgba8 {
    pub fn filled(width: u32, height: u32, rgba: [u8; 4]) -> Rgba8 {
        Rgba8 { width, height, data: rgba.repeat((width * height) as usize) }
    }

    /// Blends `rgba` over the rectangle, clipped to the image (alpha 255 = replace).
    pub fn fill(&mut self, x: i64, y: i64, w: i64, h: i64, rgba: [u8; 4]) {
        let (x0, y0) = (x.max(0), y.max(0));
        let (x1, y1) = ((x + w).min(self.width as i64), (y + h).min(self.height as i64));
        let a = rgba[3] as u32;
        for py in y0..y1 {
            for px in x0..x1 {
                let i = 4 * (py as usize * self.width as usize + px as usize);
                for (old, new) in self.data[i..i + 3].iter_mut().zip(rgba) {
                    *old = ((new as u32 * a + *old as u32 * (255 - a) + 127) / 255) as u8;
                }
            }
        }
    }

    /// Copies `src` with its top-left corner at (x, y).
    pub fn paste(&mut self, src: &Rgba8, x: u32, y: u32) {
        let row = 4 * src.width.min(self.width.saturating_sub(x)) as usize;
        for sy in 0..src.height.min(self.height.saturating_sub(y)) {
            let from = 4 * (sy * src.width) as usize;
            let to = 4 * ((y + sy) * self.width + x) as usize;
            self.data[to..to + row].copy_from_slice(&src.data[from..from + row]);
        }
    }

    /// Glyph scale for labels: 8 px glyphs × 1..=4, about 1/32 of the height.
    pub fn label_scale(&self) -> u32 {
        (self.height / 256).clamp(1, 4)
    }

    /// Writes `text` (ASCII; anything else as '?') in white on a dark translucent box whose
    /// top-left corner is (x, y); right-aligned to x instead when `right` is set. Returns the
    /// box's width.
    pub fn label(&mut self, text: &str, x: i64, y: i64, right: bool) -> i64 {
        if text.is_empty() {
            return 0;
        }
        let scale = self.label_scale() as i64;
        let pad = 3 * scale;
        let (w, h) = (8 * scale * text.chars().count() as i64 + 2 * pad, 8 * scale + 2 * pad);
        let x = if right { x - w } else { x };
        self.fill(x, y, w, h, [0, 0, 0, 170]);
        for (k, ch) in text.chars().enumerate() {
            let glyph = font8x8::legacy::BASIC_LEGACY[if ch.is_ascii() { ch as usize } else { '?' as usize }];
            for (gy, bits) in glyph.iter().enumerate() {
                for gx in 0..8 {
                    if bits >> gx & 1 == 1 {
                        let px = x + pad + (8 * k as i64 + gx) * scale;
                        self.fill(px, y + pad + gy as i64 * scale, scale, scale, [255, 255, 255, 255]);
                    }
                }
            }
        }
        w
    }
}

/// The split screen: the left half of `a`, the right half of `b`, a dark divider between them,
/// each half labelled at the top next to the divider.
pub fn split(a: &Rgba8, b: &Rgba8, labels: [&str; 2]) -> Result<Rgba8> {
    anyhow::ensure!((a.width, a.height) == (b.width, b.height), "the two images differ in size");
    let mut out = b.clone();
    let half = a.width / 2;
    for y in 0..a.height as usize {
        let row = 4 * y * a.width as usize;
        out.data[row..row + 4 * half as usize].copy_from_slice(&a.data[row..row + 4 * half as usize]);
    }
    let scale = out.label_scale() as i64;
    out.fill(half as i64 - scale, 0, 2 * scale, a.height as i64, [20, 20, 20, 255]);
    let margin = 4 * scale;
    out.label(labels[0], half as i64 - margin, margin, true);
    out.label(labels[1], half as i64 + margin, margin, false);
    Ok(out)
}

/// Tiles of one size in rows of `columns`, each labelled in its top-left corner, separated by
/// thin dark lines.
pub fn grid(tiles: &[(&str, &Rgba8)], columns: u32) -> Rgba8 {
    let (w, h) = tiles.first().map_or((0, 0), |(_, t)| (t.width, t.height));
    let rows = (tiles.len() as u32).div_ceil(columns.max(1));
    let mut out = Rgba8::filled(w * columns, h * rows, [20, 20, 20, 255]);
    let scale = out.label_scale().min(tiles.first().map_or(1, |(_, t)| t.label_scale())) as i64;
    for (k, (label, tile)) in tiles.iter().enumerate() {
        let (x, y) = ((k as u32 % columns) * w, (k as u32 / columns) * h);
        out.paste(tile, x, y);
        let line = [20, 20, 20, 255];
        out.fill(x as i64, y as i64, scale, h as i64, line);
        out.fill(x as i64, y as i64, w as i64, scale, line);
        out.label(label, x as i64 + 4 * scale, y as i64 + 4 * scale, false);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_takes_halves_and_draws_the_divider_and_labels() {
        let (a, b) = (Rgba8::filled(64, 40, [255, 0, 0, 255]), Rgba8::filled(64, 40, [0, 0, 255, 255]));
        let out = split(&a, &b, ["A", "B"]).unwrap();
        let px = |x: u32, y: u32| &out.data[4 * (y * 64 + x) as usize..4 * (y * 64 + x) as usize + 3];
        assert_eq!(px(2, 39), [255, 0, 0]);
        assert_eq!(px(61, 39), [0, 0, 255]);
        assert_eq!(px(32, 39), [20, 20, 20]);
        // A white pixel of each label's glyph, on its own side of the divider.
        let white = |xs: std::ops::Range<u32>| xs.into_iter().any(|x| (0..20).any(|y| px(x, y) == [255, 255, 255]));
        assert!(white(0..31) && white(33..64));
    }

    #[test]
    fn grid_places_tiles_in_rows() {
        let tiles: Vec<Rgba8> = (0..5).map(|k| Rgba8::filled(10, 8, [k * 40, 0, 0, 255])).collect();
        let named: Vec<(&str, &Rgba8)> = tiles.iter().map(|t| ("", t)).collect();
        let out = grid(&named, 3);
        assert_eq!((out.width, out.height), (30, 16));
        assert_eq!(out.data[4 * (12 * 30 + 15) as usize], 160, "tile 4 is the second of row 2");
        assert_eq!(out.data[4 * (12 * 30 + 25) as usize], 20, "the sixth cell is empty");
    }
}
