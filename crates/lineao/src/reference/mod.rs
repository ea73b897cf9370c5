//! The CPU reference: every screen-space pass in plain Rust over f32 images.
//!
//! Each method's reference lives in its folder (`method/<name>/reference.rs`) and is
//! re-exported here, beside the shared passes'. It exists to prove the shaders. Tests read the GPU's inputs back, run these functions on
//! exactly those inputs (same noise) and compare pixel by pixel (docs/reference.md "GPU vs CPU
//! agreement"). The arithmetic follows the WGSL line by line, in f32 and in the same order, so
//! the two differ only by rounding inside the GPU (fused multiply-adds, `pow`, `sqrt`).

mod bilateral;
pub mod cull;
pub mod tubes;
mod volume_ao;

pub use crate::image::{Image, NdImage};
pub use crate::method::line_ao::reference::{
    LineAoParams, OUTER_DEPTH_TOLERANCE, delta, depth_weight, hermite, light_weight, line_ao, line_ao_flip_bound,
    line_ao_pixel, line_ao_reference_flip_bound, representative_pixel, upsample_outer, whole_exponent, whole_pow,
};
pub use crate::method::raytraced::reference::ray_denoise;
pub use crate::method::ssao::reference::{SSAO_EPSILON, SsaoParams, ViewParams, ssao, ssao_blur, ssao_pixel};
pub use crate::method::vo_area::reference::{
    MomentsImage, moments_pyramid, moments_trilinear, vo_area, vo_sigma_floor,
};
pub use crate::method::vo_line::reference::{
    VoParams, vo_chord, vo_chord_half, vo_combine, vo_line, vo_line_pixel, vo_line_sample, vo_plane, vo_reflect,
    vo_sample, vo_visible,
};
pub use bilateral::{bilateral, bilateral_where};
pub use volume_ao::{unpack_octants, volume_ao};

const BINOMIAL: [f32; 5] = [0.0625, 0.25, 0.375, 0.25, 0.0625];

/// The separable binomial [1 4 6 4 1]/16 of `src` around `centre`, clamp-to-edge
/// (`shared/nd.wgsl::binomial_5x5`), on every channel.
pub fn binomial_5x5<const N: usize>(src: &Image<[f32; N]>, centre: [i64; 2]) -> [f32; N] {
    let mut sum = [0.0f32; N];
    for (dy, wy) in BINOMIAL.iter().enumerate() {
        let mut row = [0.0f32; N];
        for (dx, wx) in BINOMIAL.iter().enumerate() {
            let t = src.clamped(centre[0] + dx as i64 - 2, centre[1] + dy as i64 - 2);
            for c in 0..N {
                row[c] += wx * t[c];
            }
        }
        for c in 0..N {
            sum[c] += wy * row[c];
        }
    }
    sum
}

/// One pyramid step (`shaders/nd_pyramid.wgsl`): ⌈W/2⌉ × ⌈H/2⌉, binomial 5 × 5 around (2x, 2y).
pub fn nd_downsample(src: &NdImage) -> NdImage {
    Image::from_fn(src.width.div_ceil(2), src.height.div_ceil(2), |x, y| {
        let sum = binomial_5x5(src, [2 * x as i64, 2 * y as i64]);
        let len = (sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]).sqrt();
        if len > 1e-6 { [sum[0] / len, sum[1] / len, sum[2] / len, sum[3]] } else { [0.0, 0.0, 0.0, sum[3]] }
    })
}

/// The pyramid of `levels` levels over `level0`.
pub fn nd_pyramid(level0: NdImage, levels: u32) -> Vec<NdImage> {
    let mut pyramid = vec![level0];
    for _ in 1..levels {
        let next = nd_downsample(pyramid.last().expect("level 0 exists"));
        pyramid.push(next);
    }
    pyramid
}

/// The nearest texel of a level of size `size` for full-resolution pixel `pixel` displaced by
/// `offset` pixels (docs/reference.md "Addressing"; `shared/nd.wgsl::level_texel`).
pub fn level_texel(pixel: [u32; 2], offset: [f32; 2], scale: [f32; 2], size: [usize; 2]) -> [i64; 2] {
    let t = |k: usize| {
        let uv = (pixel[k] as f32 + 0.5 + offset[k]) * scale[k];
        (uv.floor() as i64).clamp(0, size[k] as i64 - 1)
    };
    [t(0), t(1)]
}

/// How the composite merges the screen-space method's occlusion with object-space AO
/// (`shaders/composite.wgsl`): `None` shows the screen-space one alone.
pub fn combine_ao(screen: f32, volume: Option<(f32, crate::VoCombine)>) -> f32 {
    match volume {
        None => screen,
        Some((v, crate::VoCombine::Product)) => 1.0 - (1.0 - screen) * (1.0 - v),
        Some((v, crate::VoCombine::Min)) => screen.max(v),
    }
}

/// The composite (`shaders/composite.wgsl`, final view) over the visible window: linear RGB.
pub fn composite(
    color: &Image<[f32; 4]>,
    specular: &Image<f32>,
    ao: &Image<f32>,
    guard: usize,
    strength: f32,
) -> Image<[f32; 3]> {
    Image::from_fn(color.width - 2 * guard, color.height - 2 * guard, |x, y| {
        let (gx, gy) = (x + guard, y + guard);
        let c = color.get(gx, gy);
        let keep = 1.0 - (strength * ao.get(gx, gy)).clamp(0.0, 1.0);
        let s = specular.get(gx, gy);
        [c[0] * keep + s, c[1] * keep + s, c[2] * keep + s]
    })
}
