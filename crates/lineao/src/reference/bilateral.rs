//! CPU reference of the separable bilateral blur (`shaders/bilateral.wgsl`).

use super::{Image, NdImage};
use crate::settings::BilateralSettings;
use crate::view_params::ViewParams;

/// x then y, each neighbour k pixels away weighing exp(−k² · 1/(2σ_s²) − Δz² · 1/(2σ_z²)) over
/// geometry pixels; background stays 0.
pub fn bilateral(ao: &Image<f32>, nd: &NdImage, view: &ViewParams, settings: &BilateralSettings) -> Image<f32> {
    bilateral_where(ao, nd, view, settings, &|_, _| true)
}

/// [`bilateral`] received only by the pixels where `receives` holds (the anatomy slices'); every
/// other geometry pixel keeps its occlusion and still gives it to its neighbours.
pub fn bilateral_where(
    ao: &Image<f32>,
    nd: &NdImage,
    view: &ViewParams,
    settings: &BilateralSettings,
    receives: &dyn Fn(usize, usize) -> bool,
) -> Image<f32> {
    let sigma_s = settings.radius_px as f32 * 0.5;
    let spatial = 1.0 / (2.0 * sigma_s * sigma_s);
    let depth = 1.0 / (2.0 * settings.depth_sigma_world * settings.depth_sigma_world);
    let r = settings.radius_px as i64;
    let geometry = |x: usize, y: usize| nd.get(x, y)[..3] != [0.0; 3];
    let half = |src: &Image<f32>, step: (i64, i64)| {
        Image::from_fn(src.width, src.height, |x, y| {
            if !geometry(x, y) {
                return 0.0;
            }
            if !receives(x, y) {
                return src.get(x, y);
            }
            let z = view.linear_depth(nd.get(x, y)[3]);
            let (mut sum, mut weight) = (0.0f32, 0.0f32);
            for k in -r..=r {
                let (sx, sy) = (x as i64 + k * step.0, y as i64 + k * step.1);
                if sx < 0 || sy < 0 || sx >= src.width as i64 || sy >= src.height as i64 {
                    continue;
                }
                let (sx, sy) = (sx as usize, sy as usize);
                if !geometry(sx, sy) {
                    continue;
                }
                let dz = view.linear_depth(nd.get(sx, sy)[3]) - z;
                let w = (-((k * k) as f32) * spatial - dz * dz * depth).exp();
                sum += w * src.get(sx, sy);
                weight += w;
            }
            sum / weight
        })
    };
    half(&half(ao, (1, 0)), (0, 1))
}
