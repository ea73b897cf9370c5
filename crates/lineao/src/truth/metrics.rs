//! How far an AO map is from the truth, over the pixels of a mask (the visible geometry).
//!
//! Per map: the bias (mean of method − truth), mean |Δ|, RMSE, Pearson's correlation and SSIM;
//! and the best single scale s, the least-squares fit of s · ao to the truth
//! (s = Σ a t / Σ a²), with bias, mean |Δ|, RMSE and SSIM again for s · ao — so a method that is
//! only too strong (a good correlation, s < 1) is told apart from one that is wrong (a poor
//! correlation whatever s).
//!
//! **SSIM** as Wang, Bovik, Sheikh and Simoncelli (IEEE TIP 2004) define it: an 11 × 11 Gaussian
//! window of σ = 1.5 (truncated at 3.5 σ), C1 = (0.01 L)², C2 = (0.03 L)² with L = 1, population
//! (not sample) variances; the map is computed on the whole image, reflecting at its borders,
//! and averaged over the mask. On the interior of an image this is what scikit-image's
//! `structural_similarity(a, b, gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
//! data_range=1)` computes; the tests check numbers from it.

use crate::image::Image;

/// Half the SSIM window's side: ⌊3.5 σ + 0.5⌋ for σ = 1.5.
pub const SSIM_RADIUS: usize = 5;
/// SSIM's Gaussian window's σ (Wang et al. 2004).
pub const SSIM_SIGMA: f64 = 1.5;
/// SSIM's C1 = (0.01 L)², L = 1.
pub const SSIM_C1: f64 = 0.01 * 0.01;
/// SSIM's C2 = (0.03 L)², L = 1.
pub const SSIM_C2: f64 = 0.03 * 0.03;

/// The error measures of one map.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Errors {
    /// The mean of method − truth.
    pub bias: f64,
    /// The mean of |method − truth|.
    pub mean_abs: f64,
    /// The root of the mean squared error.
    pub rmse: f64,
    /// SSIM, averaged over the compared pixels.
    pub ssim: f64,
}

/// A method's AO against the truth.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Scores {
    /// Pixels compared.
    pub pixels: usize,
    /// The method's mean.
    pub mean_method: f64,
    /// The truth's mean.
    pub mean_truth: f64,
    /// Pearson's correlation (0 when either map is constant).
    pub correlation: f64,
    /// The map as it is.
    pub raw: Errors,
    /// The best single scale s, and the errors of s · ao.
    pub scale: f64,
    /// The errors of s · ao.
    pub scaled: Errors,
}

/// The cheap part of [`score`]: means, bias, mean |Δ|, RMSE and correlation, without SSIM's
/// windows (what `lineao score` reports against its second truth).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Agreement {
    /// Pixels compared.
    pub pixels: usize,
    /// The method's mean.
    pub mean_method: f64,
    /// The truth's mean.
    pub mean_truth: f64,
    /// The mean of method − truth.
    pub bias: f64,
    /// The mean of |method − truth|.
    pub mean_abs: f64,
    /// The root of the mean squared error.
    pub rmse: f64,
    /// Pearson's correlation (0 when either map is constant).
    pub correlation: f64,
}

/// [`Agreement`] of `method` with `truth` over the pixels where `mask` holds.
pub fn agreement(method: &[f32], truth: &[f32], mask: &[bool]) -> Agreement {
    let pairs = || method.iter().zip(truth).zip(mask).filter(|(_, m)| **m).map(|((&a, &t), _)| (a as f64, t as f64));
    let (mut n, mut sa, mut st, mut abs, mut sq) = (0usize, 0.0, 0.0, 0.0, 0.0);
    for (a, t) in pairs() {
        n += 1;
        sa += a;
        st += t;
        abs += (a - t).abs();
        sq += (a - t) * (a - t);
    }
    if n == 0 {
        return Agreement::default();
    }
    let count = n as f64;
    Agreement {
        pixels: n,
        mean_method: sa / count,
        mean_truth: st / count,
        bias: (sa - st) / count,
        mean_abs: abs / count,
        rmse: (sq / count).sqrt(),
        correlation: correlation(method, truth, mask),
    }
}

/// Pearson's correlation of `a` and `b` over the pixels where `mask` holds (0 when either is
/// constant there): [`score`]'s `correlation` alone, without the SSIM windows.
pub fn correlation(a: &[f32], b: &[f32], mask: &[bool]) -> f64 {
    let pairs = || a.iter().zip(b).zip(mask).filter(|(_, m)| **m).map(|((&a, &b), _)| (a as f64, b as f64));
    let (n, sa, sb) = pairs().fold((0usize, 0.0, 0.0), |(n, sa, sb), (a, b)| (n + 1, sa + a, sb + b));
    if n == 0 {
        return 0.0;
    }
    let (ma, mb) = (sa / n as f64, sb / n as f64);
    let (saa, sbb, sab) = pairs().fold((0.0, 0.0, 0.0), |(saa, sbb, sab), (a, b)| {
        (saa + (a - ma) * (a - ma), sbb + (b - mb) * (b - mb), sab + (a - ma) * (b - mb))
    });
    if saa > 0.0 && sbb > 0.0 { sab / (saa * sbb).sqrt() } else { 0.0 }
}

/// Scores `method` against `truth` (same size) over the pixels where `mask` holds.
pub fn score(method: &Image<f32>, truth: &Image<f32>, mask: &[bool]) -> Scores {
    assert_eq!((method.width, method.height), (truth.width, truth.height), "maps of different sizes");
    assert_eq!(mask.len(), truth.data.len(), "a mask of another size");
    let pairs =
        || method.data.iter().zip(&truth.data).zip(mask).filter(|(_, m)| **m).map(|((&a, &t), _)| (a as f64, t as f64));
    let pixels = pairs().count();
    if pixels == 0 {
        return Scores::default();
    }
    let n = pixels as f64;
    let (sa, st) = pairs().fold((0.0, 0.0), |(sa, st), (a, t)| (sa + a, st + t));
    let (ma, mt) = (sa / n, st / n);
    let (mut saa, mut stt, mut sat, mut raw_at, mut raw_aa) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (a, t) in pairs() {
        saa += (a - ma) * (a - ma);
        stt += (t - mt) * (t - mt);
        sat += (a - ma) * (t - mt);
        raw_at += a * t;
        raw_aa += a * a;
    }
    let correlation = if saa > 0.0 && stt > 0.0 { sat / (saa * stt).sqrt() } else { 0.0 };
    let scale = if raw_aa > 0.0 { raw_at / raw_aa } else { 0.0 };
    let errors = |s: f64| {
        let (mut bias, mut abs, mut sq) = (0.0, 0.0, 0.0);
        for (a, t) in pairs() {
            let d = s * a - t;
            bias += d;
            abs += d.abs();
            sq += d * d;
        }
        let scaled = Image {
            width: method.width,
            height: method.height,
            data: method.data.iter().map(|&a| (s * a as f64) as f32).collect(),
        };
        Errors { bias: bias / n, mean_abs: abs / n, rmse: (sq / n).sqrt(), ssim: mean_ssim(&scaled, truth, mask) }
    };
    Scores { pixels, mean_method: ma, mean_truth: mt, correlation, raw: errors(1.0), scale, scaled: errors(scale) }
}

/// The SSIM map of `a` against `b` (module doc).
pub fn ssim_map(a: &Image<f32>, b: &Image<f32>) -> Image<f32> {
    let (w, h) = (a.width, a.height);
    let weights: Vec<f64> = {
        let raw: Vec<f64> = (0..=2 * SSIM_RADIUS)
            .map(|i| {
                let x = i as f64 - SSIM_RADIUS as f64;
                (-x * x / (2.0 * SSIM_SIGMA * SSIM_SIGMA)).exp()
            })
            .collect();
        let sum: f64 = raw.iter().sum();
        raw.iter().map(|v| v / sum).collect()
    };
    // scipy's `reflect`: d c b a | a b c d.
    let reflect = |i: i64, n: usize| -> usize {
        let n = n as i64;
        let mut i = i;
        loop {
            if i < 0 {
                i = -i - 1;
            } else if i >= n {
                i = 2 * n - i - 1;
            } else {
                return i as usize;
            }
        }
    };
    // The window's taps along one axis of length n, as (index, weight) lists per position: the
    // interior's are contiguous, the border's reflected. Made once per axis.
    let taps = |n: usize| -> Vec<[(usize, f64); 2 * SSIM_RADIUS + 1]> {
        (0..n)
            .map(|x| std::array::from_fn(|k| (reflect(x as i64 + k as i64 - SSIM_RADIUS as i64, n), weights[k])))
            .collect()
    };
    let (along_x, along_y) = (taps(w), taps(h));
    // Separable: along x into `rows`, then along y.
    let blur = |f: &[f64]| -> Vec<f64> {
        let mut rows = vec![0.0; w * h];
        for y in 0..h {
            let line = &f[y * w..(y + 1) * w];
            for (x, taps) in along_x.iter().enumerate() {
                rows[y * w + x] = taps.iter().map(|&(i, wk)| wk * line[i]).sum();
            }
        }
        let mut out = vec![0.0; w * h];
        for (y, taps) in along_y.iter().enumerate() {
            let row = &mut out[y * w..(y + 1) * w];
            for &(j, wk) in taps {
                for (o, r) in row.iter_mut().zip(&rows[j * w..(j + 1) * w]) {
                    *o += wk * r;
                }
            }
        }
        out
    };
    let av: Vec<f64> = a.data.iter().map(|&v| v as f64).collect();
    let bv: Vec<f64> = b.data.iter().map(|&v| v as f64).collect();
    let product = |f: fn(f64, f64) -> f64| -> Vec<f64> { av.iter().zip(&bv).map(|(&a, &b)| f(a, b)).collect() };
    let (ua, ub) = (blur(&av), blur(&bv));
    let uaa = blur(&product(|a, _| a * a));
    let ubb = blur(&product(|_, b| b * b));
    let uab = blur(&product(|a, b| a * b));
    let data = (0..w * h)
        .map(|i| {
            let (va, vb, vab) = (uaa[i] - ua[i] * ua[i], ubb[i] - ub[i] * ub[i], uab[i] - ua[i] * ub[i]);
            (((2.0 * ua[i] * ub[i] + SSIM_C1) * (2.0 * vab + SSIM_C2))
                / ((ua[i] * ua[i] + ub[i] * ub[i] + SSIM_C1) * (va + vb + SSIM_C2))) as f32
        })
        .collect();
    Image { width: w, height: h, data }
}

/// The mean SSIM over the mask's pixels (1 for identical maps).
pub fn mean_ssim(a: &Image<f32>, b: &Image<f32>, mask: &[bool]) -> f64 {
    let map = ssim_map(a, b);
    let (sum, count) =
        map.data.iter().zip(mask).filter(|(_, m)| **m).fold((0.0, 0usize), |(s, c), (&v, _)| (s + v as f64, c + 1));
    if count == 0 { 0.0 } else { sum / count as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> Image<f32> {
        Image::from_fn(w, h, f)
    }

    #[test]
    fn identical_maps_score_perfectly() {
        let a = image(40, 30, |x, y| ((x * 7 + y * 3) % 11) as f32 / 11.0);
        let mask = vec![true; 1200];
        let s = score(&a, &a, &mask);
        assert_eq!(s.raw.rmse, 0.0);
        assert_eq!(s.raw.bias, 0.0);
        assert!((s.raw.ssim - 1.0).abs() < 1e-9);
        assert!((s.correlation - 1.0).abs() < 1e-12);
        assert!((s.scale - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_known_scale_and_offset_are_recovered() {
        let truth = image(32, 32, |x, y| 0.1 + 0.8 * ((x + 2 * y) % 17) as f32 / 17.0);
        let mask: Vec<bool> = (0..32 * 32).map(|i| i % 3 != 0).collect();
        // Twice the truth: s = 1/2 exactly, and after it no error.
        let doubled = Image { data: truth.data.iter().map(|t| 2.0 * t).collect(), ..truth.clone() };
        let s = score(&doubled, &truth, &mask);
        assert!((s.scale - 0.5).abs() < 1e-7, "{}", s.scale);
        assert!(s.scaled.rmse < 1e-7 && s.scaled.bias.abs() < 1e-7);
        assert!((s.raw.bias - s.mean_truth).abs() < 1e-6, "bias {} = the truth's mean", s.raw.bias);
        // An offset: the bias and RMSE are the offset.
        let shifted = Image { data: truth.data.iter().map(|t| t + 0.125).collect(), ..truth.clone() };
        let s = score(&shifted, &truth, &mask);
        assert!((s.raw.bias - 0.125).abs() < 1e-6 && (s.raw.rmse - 0.125).abs() < 1e-6);
        assert!((s.raw.mean_abs - 0.125).abs() < 1e-6);
        assert!((s.correlation - 1.0).abs() < 1e-9);
        // Negated around the mean: correlation −1.
        let flipped = Image { data: truth.data.iter().map(|t| 1.0 - t).collect(), ..truth.clone() };
        assert!((score(&flipped, &truth, &mask).correlation + 1.0).abs() < 1e-9);
    }

    /// A fixed pair of 24 × 20 images scored by scikit-image 0.26.0
    /// (`structural_similarity(a, b, gaussian_weights=True, sigma=1.5,
    /// use_sample_covariance=False, data_range=1.0)`, whose mean leaves out 5 pixels at each
    /// border), with a and b made as below in numpy (float64 of these f32 values).
    #[test]
    fn ssim_equals_an_independent_implementation() {
        let (w, h) = (24, 20);
        let a = image(w, h, |x, y| (((x * 13 + y * 7) % 23) as f32 / 22.0) * 0.7 + 0.1 * (y as f32 / 19.0));
        let b = image(w, h, |x, y| {
            let v = a.get(x, y) * 0.8 + 0.15 * (((x * 5 + y * 11) % 9) as f32 / 8.0);
            v.min(1.0)
        });
        let interior: Vec<bool> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                (5..w - 5).contains(&x) && (5..h - 5).contains(&y)
            })
            .collect();
        let ssim = mean_ssim(&a, &b, &interior);
        assert!((ssim - SKIMAGE_SSIM).abs() < 1e-5, "ours {ssim}, scikit-image {SKIMAGE_SSIM}");
    }

    const SKIMAGE_SSIM: f64 = 0.946_633_248_898_704_7;
}
