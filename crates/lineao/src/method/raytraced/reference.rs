//! CPU reference of the ray tracer's edge-aware denoiser (`ray_denoise.wgsl`).

use super::settings::RayDenoiseSettings;
use crate::image::{Image, NdImage};
use crate::view_params::ViewParams;

/// The own segment of a pixel without one (surfaces, tubes).
const NONE: u32 = u32::MAX;

/// The denoised AO of the ray tracer's `accumulation` (per pixel: the sums of the rays' values
/// and of their squares as f32 bits, the own segment, the buried flag) over `nd` after `rays`
/// rays per pixel of lines or `tubes`.
pub fn ray_denoise(
    accumulation: &Image<[u32; 4]>,
    nd: &NdImage,
    view: &ViewParams,
    settings: &RayDenoiseSettings,
    (rays, tubes): (u32, bool),
) -> Image<f32> {
    let spatial = settings.spatial(rays, tubes);
    let radius = if spatial == 0.0 { 0 } else { settings.radius_px as i64 };
    let background = |texel: [f32; 4]| texel[..3] == [0.0; 3];
    let unit = |t: [f32; 4]| {
        let l = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        [t[0] / l, t[1] / l, t[2] / l]
    };
    Image::from_fn(nd.width, nd.height, |x, y| {
        let (here, centre) = (nd.get(x, y), accumulation.get(x, y));
        if background(here) || rays == 0 {
            return 0.0;
        }
        let n = unit(here);
        let z = view.linear_depth(here[3]);
        let own = centre[2];
        let (mut sum, mut weight) = (0.0f32, 0.0f32);
        for dy in -radius..=radius {
            for dx in -radius..=radius {
                let (qx, qy) = (x as i64 + dx, y as i64 + dy);
                if qx < 0 || qy < 0 || qx >= nd.width as i64 || qy >= nd.height as i64 {
                    continue;
                }
                let (texel, s) = (nd.get(qx as usize, qy as usize), accumulation.get(qx as usize, qy as usize));
                if background(texel) {
                    continue;
                }
                let same = if own != NONE {
                    s[2] != NONE && s[2].abs_diff(own) <= settings.reach_vertices
                } else {
                    s[2] == NONE && (view.linear_depth(texel[3]) - z).abs() <= settings.depth_tolerance * z
                };
                if !same {
                    continue;
                }
                let m = unit(texel);
                let facing = (n[0] * m[0] + n[1] * m[1] + n[2] * m[2]).max(0.0);
                let w = (-((dx * dx + dy * dy) as f32) * spatial).exp() * facing.powf(settings.normal_power);
                sum += w * (f32::from_bits(s[0]) / rays as f32);
                weight += w;
            }
        }
        sum / weight
    })
}
