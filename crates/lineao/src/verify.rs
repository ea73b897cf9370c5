//! Proving the GPU against the CPU reference (its targets read back by [`crate::readback`]): the
//! agreement check of docs/reference.md ("GPU vs CPU agreement"): ≥ 99.5 % of geometry pixels within
//! 1e-3, and every pixel within a bound of a few flipped samples.

use crate::Error;
use crate::camera::FrameView;
use crate::image::{Image, NdImage};
use crate::settings::ChainSettings;

/// How two images differ.
#[derive(Clone, Debug, PartialEq)]
pub struct Agreement {
    /// Pixels compared (the mask's).
    pub pixels: usize,
    /// Share of them within `tolerance`.
    pub fraction_within: f64,
    /// Largest absolute difference and where.
    pub worst: f32,
    /// Where the largest difference is.
    pub worst_pixel: (usize, usize),
    /// The mean absolute difference.
    pub mean_abs: f64,
}

impl std::fmt::Display for Agreement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} pixels, {:.4} % within tolerance, mean |Δ| {:.2e}, worst |Δ| {:.3e} at {:?}",
            self.pixels,
            100.0 * self.fraction_within,
            self.mean_abs,
            self.worst,
            self.worst_pixel
        )
    }
}

/// Compares `a` and `b` on the pixels where `mask` holds.
pub fn compare(a: &Image<f32>, b: &Image<f32>, tolerance: f32, mask: impl Fn(usize, usize) -> bool) -> Agreement {
    assert_eq!((a.width, a.height), (b.width, b.height), "images differ in size");
    let (mut pixels, mut within, mut sum) = (0usize, 0usize, 0.0f64);
    let (mut worst, mut worst_pixel) = (0.0f32, (0, 0));
    for y in 0..a.height {
        for x in 0..a.width {
            if !mask(x, y) {
                continue;
            }
            let d = (a.get(x, y) - b.get(x, y)).abs();
            let d = if d.is_nan() { f32::INFINITY } else { d };
            pixels += 1;
            sum += d as f64;
            within += (d <= tolerance) as usize;
            if d > worst {
                (worst, worst_pixel) = (d, (x, y));
            }
        }
    }
    Agreement {
        pixels,
        fraction_within: if pixels == 0 { 1.0 } else { within as f64 / pixels as f64 },
        worst,
        worst_pixel,
        mean_abs: if pixels == 0 { 0.0 } else { sum / pixels as f64 },
    }
}

/// What a frame's method read, read back from the GPU: the inputs its CPU reference runs on.
pub struct FrameInputs<'a> {
    /// The chain's settings for the frame.
    pub settings: &'a ChainSettings,
    /// The view as the passes saw it (with its guard band).
    pub view: &'a FrameView,
    /// The ND pyramid; level 0 is the guard-banded frame.
    pub nd: &'a [NdImage],
    /// The zoom map z(P).
    pub zoom: &'a Image<f32>,
}

/// The CPU reference's occlusion of a frame, before any blur, and docs/reference.md's bound on
/// any one pixel's difference (a few samples that flip between inside and outside in f32).
pub struct ReferenceAo {
    /// The occlusion, at the frame's guard-banded size.
    pub ao: Image<f32>,
    /// The largest difference any pixel may have ([`check_policy`]'s `every_pixel_bound`).
    pub every_pixel_bound: f32,
}

/// The CPU reference of `inputs`' method on exactly those inputs (each method's
/// `reference.rs`, named by its registry entry); `None` for a method whose frame has no
/// reference of its own here (`none`, VO, the ray tracer: their tests hold them to theirs).
pub fn reference_ao(inputs: &FrameInputs) -> Option<Result<ReferenceAo, Error>> {
    inputs.settings.method.info().reference.map(|reference| reference(inputs))
}

/// Checks the agreement policy on geometry pixels (non-background in `nd0`) and returns the
/// statistics, or an error message that names the worst pixel and the fraction.
pub fn check_policy(
    gpu: &Image<f32>,
    cpu: &Image<f32>,
    nd0: &NdImage,
    every_pixel_bound: f32,
) -> Result<Agreement, String> {
    let geometry = |x: usize, y: usize| nd0.get(x, y)[..3] != [0.0; 3];
    let stats = compare(gpu, cpu, 1e-3, geometry);
    let everywhere = compare(gpu, cpu, every_pixel_bound, |_, _| true);
    if stats.fraction_within < 0.995 || everywhere.worst > every_pixel_bound {
        return Err(format!("GPU vs CPU: {stats}; every-pixel bound {every_pixel_bound}: {everywhere}"));
    }
    Ok(stats)
}
