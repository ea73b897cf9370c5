//! Legibility: do visibly darker pixels lie deeper?
//!
//! LineAO exists so that people can see how dense bundles of lines lie in depth ("simultaneous
//! depiction of local and global line structures"). Under diffuse light the eye reads *darker as
//! deeper* (Langer & Bülthoff 2000; Scaccia & Langer 2018 for cluttered scenes), so a picture
//! conveys depth order where its darkening agrees with depth. This module measures that
//! agreement (docs/reference.md "Legibility"):
//!
//! - **Darkening** D = 1 − Y/Y_none per geometry pixel, Y the linear-light luminance of the
//!   composite and Y_none that of the same frame without AO ([`Shading::darkening`]).
//! - **Pairs** (p, q): p uniform over the geometry pixels, q = p + o with o uniform over the
//!   integer offsets of the disc of radius r (the centre left out), both geometry, their
//!   normalized depths apart by more than [`DEPTH_SEPARATION`]. Pairs that fail are drawn again,
//!   so every valid (p, o) is equally likely.
//! - A pair is **concordant** when D differs by more than [`VISIBLE_DARKENING`] with the sign of
//!   the depth difference (the deeper pixel darker), **discordant** when it differs by that much
//!   the other way; pairs whose darkening differs by less are *invisible* and count in neither.
//! - **L_r** = (concordant − discordant) / pairs: 1 when every pair's depth order is visible and
//!   right, −1 when it is visible and inverted, 0 with no AO (nothing is visible) and for random
//!   darkening (as many pairs each way). At r = 1 %, 4 % and 15 % of the image width
//!   ([`SCALES`]: local, bundle, global).
//! - Also the mean darkening and the **near-black** share (D > [`NEAR_BLACK`]): a picture that
//!   is legible only because it is black, or so faint that nobody sees it, fails elsewhere.
//!
//! L is estimated from [`PAIRS`] pairs per scale drawn with a fixed seed, so its standard error
//! is at most 1/√PAIRS = 0.002 (each pair counts −1, 0 or 1) and the same picture always gets
//! the same number; [`Pairs::exact`] enumerates every pair (small images, tests). A frame with
//! fewer than [`MIN_PIXELS`] geometry pixels has no legibility ([`Absent`]), never a 0.

use crate::image::Image;
use crate::noise::pcg_hash;

/// The pairs' disc radii as shares of the image width: local, bundle, global.
pub const SCALES: [f64; 3] = [0.01, 0.04, 0.15];
/// Pairs whose normalized depths differ by at most this are not ordered in depth (0.5 % of the
/// scene's depth range: about one line width in a whole brain).
pub const DEPTH_SEPARATION: f32 = 0.005;
/// The least difference in darkening that counts as visible (3 %: the Weber fraction of
/// luminance is about 1–2 % at best, a few percent in cluttered pictures).
pub const VISIBLE_DARKENING: f32 = 0.03;
/// A pixel darkened by more than this is near-black: its colour is gone.
pub const NEAR_BLACK: f32 = 0.8;
/// The fewest geometry pixels a frame needs for its legibility to mean something.
pub const MIN_PIXELS: usize = 100;
/// Pairs per scale: a standard error of at most 0.002, so L is stable to ±0.005.
pub const PAIRS: usize = 250_000;
/// The pairs' seed.
pub const SEED: u32 = 1;

/// How legible one picture is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Legibility {
    /// L_r at each of [`SCALES`].
    pub scales: [f64; 3],
    /// Mean darkening over the geometry pixels.
    pub mean_darkening: f64,
    /// Share of geometry pixels with D > [`NEAR_BLACK`].
    pub near_black: f64,
    /// Geometry pixels measured.
    pub pixels: usize,
}

impl Legibility {
    /// The mean of L over the three scales: the fit's objective.
    pub fn mean(&self) -> f64 {
        self.scales.iter().sum::<f64>() / self.scales.len() as f64
    }
}

/// Why a frame has no legibility.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Absent {
    #[error("{0} geometry pixels, fewer than the {MIN_PIXELS} legibility needs")]
    /// Fewer geometry pixels than legibility needs.
    TooFewPixels(usize),
    /// No pair of pixels far enough apart in depth.
    #[error("no two geometry pixels within {radius_px:.1} px lie apart in depth by more than {DEPTH_SEPARATION}")]
    NoPairs {
        /// The pairs' radius in pixels.
        radius_px: f64,
    },
}

/// What AO darkens in a frame, per pixel in linear light: the luminance of the lines' colour,
/// which the composite multiplies by 1 − clamp(strength · ao, 0, 1), and the frame's luminance
/// without AO (that colour plus the lines' specular, which AO leaves).
#[derive(Clone, Debug)]
pub struct Shading {
    luminance: Vec<f32>,
    specular: Vec<f32>,
}

impl Shading {
    /// From the frame's linear RGB colours and specular luminances (Rec. 709 luminance).
    pub fn new(color: &[[f32; 4]], specular: &[f32]) -> Shading {
        let luminance = color.iter().map(|c| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]).collect();
        Shading { luminance, specular: specular.to_vec() }
    }

    /// The composite's linear-light luminance at pixel `i` with occlusion `a` (clamped as the
    /// composite clamps it): lum (1 − a) + specular.
    pub fn composite(&self, i: usize, a: f32) -> f32 {
        self.luminance[i] * (1.0 - a.clamp(0.0, 1.0)) + self.specular[i]
    }

    /// D = 1 − Y/Y_none of the composite with occlusion clamp(strength · ao, 0, 1), which is
    /// lum · a / (lum + specular); 0 where Y_none is 0 (nothing to darken).
    pub fn darkening(&self, ao: &[f32], strength: f32) -> Vec<f32> {
        ao.iter()
            .zip(&self.luminance)
            .zip(&self.specular)
            .map(|((&a, &l), &s)| if l + s > 0.0 { l * (strength * a).clamp(0.0, 1.0) / (l + s) } else { 0.0 })
            .collect()
    }
}

/// The pairs of one frame at each scale, each stored deeper pixel first.
#[derive(Clone, Debug)]
pub struct Pairs {
    /// Per scale: (deeper, shallower) pixel indices.
    pub scales: [Vec<(u32, u32)>; 3],
    /// Geometry pixels.
    pub pixels: usize,
}

/// The integer offsets o ≠ 0 with |o| ≤ r.
fn disc(radius_px: f64) -> Vec<(i32, i32)> {
    let r = radius_px.floor() as i32;
    let mut offsets = Vec::new();
    for dy in -r..=r {
        for dx in -r..=r {
            let d2 = (dx * dx + dy * dy) as f64;
            if d2 > 0.0 && d2 <= radius_px * radius_px {
                offsets.push((dx, dy));
            }
        }
    }
    offsets
}

/// The disc radius in pixels of scale `s` on an image `width` pixels wide (at least one pixel,
/// so that tiny images still have neighbours).
pub fn radius_px(scale: f64, width: usize) -> f64 {
    (scale * width as f64).max(1.0)
}

impl Pairs {
    /// [`PAIRS`] pairs per scale drawn with [`SEED`].
    pub fn sample(depth: &Image<f32>, mask: &[bool]) -> Result<Pairs, Absent> {
        Pairs::sample_n(depth, mask, PAIRS, SEED)
    }

    /// `count` pairs per scale drawn with `seed`; a scale gives up after 64 × `count` draws
    /// (its pairs are then fewer, or none: [`Absent::NoPairs`]).
    pub fn sample_n(depth: &Image<f32>, mask: &[bool], count: usize, seed: u32) -> Result<Pairs, Absent> {
        let geometry = geometry_pixels(depth, mask)?;
        let (w, h) = (depth.width as i32, depth.height as i32);
        let mut scales: [Vec<(u32, u32)>; 3] = Default::default();
        for (k, &scale) in SCALES.iter().enumerate() {
            let radius = radius_px(scale, depth.width);
            let offsets = disc(radius);
            let pairs = &mut scales[k];
            pairs.reserve(count);
            let mut counter = pcg_hash(seed ^ pcg_hash(k as u32 + 1));
            let mut next = || {
                counter = counter.wrapping_add(1);
                pcg_hash(counter ^ pcg_hash(counter.rotate_left(16)))
            };
            for _ in 0..64 * count {
                if pairs.len() == count {
                    break;
                }
                let p = geometry[((next() as u64 * geometry.len() as u64) >> 32) as usize];
                let (dx, dy) = offsets[((next() as u64 * offsets.len() as u64) >> 32) as usize];
                let (x, y) = ((p % depth.width as u32) as i32 + dx, (p / depth.width as u32) as i32 + dy);
                if x < 0 || y < 0 || x >= w || y >= h {
                    continue;
                }
                let q = (y * w + x) as u32;
                if let Some(pair) = ordered(depth, mask, p, q) {
                    pairs.push(pair);
                }
            }
            if pairs.is_empty() {
                return Err(Absent::NoPairs { radius_px: radius });
            }
        }
        Ok(Pairs { scales, pixels: geometry.len() })
    }

    /// Every valid pair: for each geometry pixel p every offset of the disc (what
    /// [`Pairs::sample`] estimates). Small images only: pixels × disc offsets pairs.
    pub fn exact(depth: &Image<f32>, mask: &[bool]) -> Result<Pairs, Absent> {
        let geometry = geometry_pixels(depth, mask)?;
        let (w, h) = (depth.width as i32, depth.height as i32);
        let mut scales: [Vec<(u32, u32)>; 3] = Default::default();
        for (k, &scale) in SCALES.iter().enumerate() {
            let radius = radius_px(scale, depth.width);
            for &p in &geometry {
                for (dx, dy) in disc(radius) {
                    let (x, y) = ((p % depth.width as u32) as i32 + dx, (p / depth.width as u32) as i32 + dy);
                    if x < 0 || y < 0 || x >= w || y >= h {
                        continue;
                    }
                    if let Some(pair) = ordered(depth, mask, p, (y * w + x) as u32) {
                        scales[k].push(pair);
                    }
                }
            }
            if scales[k].is_empty() {
                return Err(Absent::NoPairs { radius_px: radius });
            }
        }
        Ok(Pairs { scales, pixels: geometry.len() })
    }

    /// L at each scale for the darkening `d` (one value per pixel of the frame).
    pub fn legibility(&self, d: &[f32]) -> [f64; 3] {
        let mut l = [0.0; 3];
        for (k, pairs) in self.scales.iter().enumerate() {
            let mut score = 0i64;
            for &(deeper, shallower) in pairs {
                let diff = d[deeper as usize] - d[shallower as usize];
                score += (diff > VISIBLE_DARKENING) as i64 - (diff < -VISIBLE_DARKENING) as i64;
            }
            l[k] = score as f64 / pairs.len() as f64;
        }
        l
    }

    /// The whole measure of the darkening `d` over `mask`.
    pub fn measure(&self, d: &[f32], mask: &[bool]) -> Legibility {
        let (mut sum, mut black, mut n) = (0.0f64, 0usize, 0usize);
        for (&d, _) in d.iter().zip(mask).filter(|(_, m)| **m) {
            sum += d as f64;
            black += (d > NEAR_BLACK) as usize;
            n += 1;
        }
        let n_f = n.max(1) as f64;
        Legibility { scales: self.legibility(d), mean_darkening: sum / n_f, near_black: black as f64 / n_f, pixels: n }
    }
}

/// The legibility of the darkening `d` of a frame whose normalized depth is `depth`, over the
/// geometry pixels `mask` ([`PAIRS`] pairs per scale).
pub fn legibility(d: &Image<f32>, depth: &Image<f32>, mask: &[bool]) -> Result<Legibility, Absent> {
    assert_eq!((d.width, d.height), (depth.width, depth.height), "darkening and depth of different sizes");
    Ok(Pairs::sample(depth, mask)?.measure(&d.data, mask))
}

fn geometry_pixels(depth: &Image<f32>, mask: &[bool]) -> Result<Vec<u32>, Absent> {
    assert_eq!(mask.len(), depth.data.len(), "a mask of another size");
    let geometry: Vec<u32> = (0..mask.len() as u32).filter(|&i| mask[i as usize]).collect();
    if geometry.len() < MIN_PIXELS {
        return Err(Absent::TooFewPixels(geometry.len()));
    }
    Ok(geometry)
}

/// (deeper, shallower) when both are geometry and apart in depth, else none.
fn ordered(depth: &Image<f32>, mask: &[bool], p: u32, q: u32) -> Option<(u32, u32)> {
    if !mask[q as usize] {
        return None;
    }
    let (dp, dq) = (depth.data[p as usize], depth.data[q as usize]);
    if (dp - dq).abs() <= DEPTH_SEPARATION {
        return None;
    }
    Some(if dp > dq { (p, q) } else { (q, p) })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame of w × h drawn like a tangle of lines: diagonal strips 3 px wide, each at one of
    /// 20 depth levels (so two strips' depths differ by 1/19 or not at all), with background
    /// where `hole` says.
    fn frame(w: usize, h: usize, hole: impl Fn(usize, usize) -> bool) -> (Image<f32>, Vec<bool>) {
        let depth = Image::from_fn(w, h, |x, y| {
            let strip = ((x + 2 * y) / 3) as u32;
            (crate::noise::pcg_hash(strip) % 20) as f32 / 19.0
        });
        let mask = (0..w * h).map(|i| !hole(i % w, i / w)).collect();
        (depth, mask)
    }

    fn stripes(x: usize, y: usize) -> bool {
        (x / 3 + y / 5).is_multiple_of(4)
    }

    #[test]
    fn no_darkening_is_zero() {
        let (depth, mask) = frame(320, 256, stripes);
        let none = vec![0.0; depth.data.len()];
        let l = legibility(&Image { data: none, ..depth.clone() }, &depth, &mask).unwrap();
        assert_eq!(l.scales, [0.0; 3]);
        assert_eq!((l.mean_darkening, l.near_black), (0.0, 0.0));
    }

    #[test]
    fn darker_where_deeper_is_legible_and_inverted_is_not() {
        let (depth, mask) = frame(320, 256, stripes);
        let deeper = legibility(&depth, &depth, &mask).unwrap();
        let inverted = Image { data: depth.data.iter().map(|d| 1.0 - d).collect(), ..depth.clone() };
        let shallower = legibility(&inverted, &depth, &mask).unwrap();
        for k in 0..3 {
            assert!(deeper.scales[k] >= 0.95, "scale {k}: {:?}", deeper.scales);
            assert!(shallower.scales[k] <= -0.95, "scale {k}: {:?}", shallower.scales);
        }
    }

    #[test]
    fn random_darkening_says_nothing() {
        let (depth, mask) = frame(320, 256, stripes);
        let random = Image {
            data: (0..depth.data.len() as u32).map(|i| crate::noise::uniform(7, 3, i)).collect(),
            ..depth.clone()
        };
        let l = legibility(&random, &depth, &mask).unwrap();
        assert!(l.scales.iter().all(|v| v.abs() < 0.02), "{:?}", l.scales);
    }

    #[test]
    fn invisible_darkening_is_zero() {
        // Deeper is darker everywhere, but never by the 3 % anybody sees.
        let (depth, mask) = frame(320, 256, stripes);
        let faint = Image { data: depth.data.iter().map(|d| 0.029 * d).collect(), ..depth.clone() };
        assert_eq!(legibility(&faint, &depth, &mask).unwrap().scales, [0.0; 3]);
    }

    #[test]
    fn too_few_pixels_are_absent_not_zero() {
        let (depth, _) = frame(64, 64, stripes);
        let mask: Vec<bool> = (0..64 * 64).map(|i| i < 99).collect();
        assert_eq!(legibility(&depth, &depth, &mask), Err(Absent::TooFewPixels(99)));
        // A flat frame: no pair is ordered in depth.
        let flat = Image::filled(64, 64, 0.5f32);
        let all = vec![true; 64 * 64];
        assert!(matches!(legibility(&flat, &flat, &all), Err(Absent::NoPairs { .. })));
    }

    #[test]
    fn near_black_and_mean() {
        let (depth, _) = frame(100, 10, |_, _| false);
        let mask = vec![true; 1000];
        let d = Image { data: (0..1000).map(|i| if i < 250 { 0.9 } else { 0.1 }).collect(), ..depth.clone() };
        let l = legibility(&d, &depth, &mask).unwrap();
        assert!((l.near_black - 0.25).abs() < 1e-12 && (l.mean_darkening - 0.3).abs() < 1e-6, "{l:?}");
    }

    #[test]
    fn the_sample_estimates_the_exact_value() {
        let (depth, mask) = frame(160, 128, stripes);
        let d = Image {
            data: depth
                .data
                .iter()
                .enumerate()
                .map(|(i, z)| 0.6 * z + 0.3 * crate::noise::uniform(5, 1, i as u32))
                .collect(),
            ..depth.clone()
        };
        let exact = Pairs::exact(&depth, &mask).unwrap().legibility(&d.data);
        let sampled = legibility(&d, &depth, &mask).unwrap().scales;
        for k in 0..3 {
            assert!((exact[k] - sampled[k]).abs() < 0.005, "scale {k}: exact {exact:?}, sampled {sampled:?}");
        }
    }

    #[test]
    fn darkening_of_a_composite() {
        // White lines without specular, with as much specular as colour, and black.
        let shading = Shading::new(&[[1.0; 4], [1.0; 4], [0.0; 4]], &[0.0, 1.0, 0.0]);
        assert_eq!(shading.darkening(&[0.5, 0.5, 0.5], 1.0), vec![0.5, 0.25, 0.0]);
        // The composite's clamp(strength · ao, 0, 1).
        assert_eq!(shading.darkening(&[0.8, 0.8, 0.8], 2.0), vec![1.0, 0.5, 0.0]);
    }

    /// The exact L of a fixed pair of 48 × 40 images, computed independently by numpy 2.4
    /// (`python3 crates/lineao/tests/legibility_numpy.py` prints them: every pixel pair of the
    /// disc enumerated by shifting whole arrays, no code shared with this module), with depth
    /// and darkening made as below in float32.
    #[test]
    fn exact_equals_an_independent_implementation() {
        let (w, h) = (48, 40);
        let depth = Image::from_fn(w, h, |x, y| ((x * 7 + y * 13) % 31) as f32 / 30.0);
        let d = Image::from_fn(w, h, |x, y| ((x * 5 + y * 3) % 17) as f32 / 16.0 * 0.5 + 0.01 * (y as f32));
        let mask: Vec<bool> = (0..w * h).map(|i| (i % w + 2 * (i / w)) % 5 != 0).collect();
        let exact = Pairs::exact(&depth, &mask).unwrap().legibility(&d.data);
        for k in 0..3 {
            assert!((exact[k] - NUMPY_EXACT[k]).abs() < 1e-12, "scale {k}: ours {exact:?}, numpy {NUMPY_EXACT:?}");
        }
    }

    const NUMPY_EXACT: [f64; 3] = [0.161_634_103_019_538_18, -0.030_997_304_582_210_24, 0.007_057_197_249_875_711];
}
