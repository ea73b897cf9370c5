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

impl Rgba8 {
    /// A colour bar at the bottom left: `colormap` from `range[0]` (left) to `range[1]`, the
    /// numbers of [`legend_labels`] under its ends and middle, `title` above it.
    pub fn legend(&mut self, title: &str, colormap: lineao::Colormap, range: [f32; 2]) {
        let scale = self.label_scale() as i64;
        let labels = legend_labels(range);
        // A label's box (`label`): 8 px glyphs and 3 px of padding each side, scaled.
        let boxed = |text: &str| 8 * scale * text.chars().count() as i64 + 6 * scale;
        let widest = labels.iter().map(|l| boxed(l)).max().unwrap_or(0);
        let (w, h) = ((self.width as i64 / 3).max(3 * widest + 8 * scale), 10 * scale);
        let margin = 8 * scale;
        let label_h = 14 * scale;
        let (x, y) = (margin, self.height as i64 - margin - label_h - h);
        self.fill(x - scale, y - scale, w + 2 * scale, h + 2 * scale, [0, 0, 0, 255]);
        for i in 0..w {
            let [r, g, b] = colormap.color(i as f32 / (w - 1) as f32).map(srgb8);
            self.fill(x + i, y, 1, h, [r, g, b, 255]);
        }
        let [low, middle, high] = labels;
        self.label(&low, x, y + h + scale, false);
        self.label(&middle, x + w / 2 - boxed(&middle) / 2, y + h + scale, false);
        self.label(&high, x + w, y + h + scale, true);
        if !title.is_empty() {
            self.label(title, x, y - 2 * scale - 14 * scale, false);
        }
    }
}

impl Rgba8 {
    /// The colours of `--color groups`, bottom left: a swatch and a name per group (the first
    /// 16; a group k shares the colour of k mod 16), "no group" in gray.
    pub fn group_legend(&mut self, names: &[&str]) {
        let scale = self.label_scale() as i64;
        let row = 14 * scale;
        let shown = names.len().min(lineao::COLORMAP_ENTRIES);
        let margin = 8 * scale;
        let top = self.height as i64 - margin - row * (shown as i64 + 1);
        let table = lineao::Colormap::Categories.table();
        let swatch = |image: &mut Rgba8, y: i64, rgb: [f32; 3]| {
            let [r, g, b] = rgb.map(srgb8);
            image.fill(margin, y + 2 * scale, row - 4 * scale, row - 4 * scale, [r, g, b, 255]);
        };
        for (k, name) in names.iter().take(shown).enumerate() {
            let y = top + k as i64 * row;
            swatch(self, y, [table[k][0], table[k][1], table[k][2]]);
            self.label(name, margin + row, y, false);
        }
        let y = top + shown as i64 * row;
        // The shaders' colour for NaN: 50 % gray, linear.
        swatch(self, y, [0.5; 3]);
        self.label("no group", margin + row, y, false);
    }
}

/// sRGB encoding of a linear value (clamped to [0, 1]).
pub fn srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 }
}

/// The linear value of an sRGB-encoded one in [0, 1] (the inverse of [`srgb`]).
pub fn linear(v: f32) -> f32 {
    if v <= 0.040_45 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

/// A linear RGB channel (clamped to [0, 1]) as an sRGB byte.
pub fn srgb8(c: f32) -> u8 {
    (srgb(c) * 255.0).round() as u8
}

/// The numbers a colour bar over `range` shows under its start, middle and end: up to three
/// decimals with the trailing zeros dropped, scientific below 0.01 and from 10 000 on.
pub fn legend_labels(range: [f32; 2]) -> [String; 3] {
    let number = |v: f32| {
        if v != 0.0 && !(0.01..10_000.0).contains(&v.abs()) {
            return format!("{v:.2e}");
        }
        let text = format!("{v:.3}");
        let text = text.trim_end_matches('0').trim_end_matches('.');
        if text == "-0" { "0".to_string() } else { text.to_string() }
    };
    [range[0], 0.5 * (range[0] + range[1]), range[1]].map(number)
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
    fn a_legend_labels_its_range_and_draws_the_colormap_between_them() {
        assert_eq!(legend_labels([0.0, 1.0]), ["0", "0.5", "1"]);
        assert_eq!(legend_labels([-2.5, 97.25]), ["-2.5", "47.375", "97.25"]);
        assert_eq!(legend_labels([0.001, 12_000.0]), ["1.00e-3", "6000", "1.20e4"]);
        let mut image = Rgba8::filled(300, 200, [255, 255, 255, 255]);
        image.legend("fa", lineao::Colormap::Gray, [0.0, 1.0]);
        // The bar's first and last columns: the colormap's ends (black and white).
        let (x0, x1, y) = (8, 8 + 100 - 1, 200 - 8 - 14 - 5);
        let at = |x: usize| &image.data[4 * (y * 300 + x)..4 * (y * 300 + x) + 3];
        assert_eq!((at(x0), at(x1)), (&[0u8, 0, 0][..], &[255u8, 255, 255][..]));
    }

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
