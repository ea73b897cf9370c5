//! CPU reference of Crytek SSAO and its 4 × 4 blur (`ssao.wgsl`, `ssao_blur.wgsl`),
//! in the shaders' f32 operation order.

use crate::image::{Image, NdImage};
use crate::verify::{FrameInputs, ReferenceAo};
pub use crate::view_params::ViewParams;

pub use super::SSAO_EPSILON;

#[derive(Clone, Copy, Debug, PartialEq)]
/// Every number SSAO reads besides the images, the kernel and the noise.
pub struct SsaoParams {
    /// The view's depth range and projection.
    pub view: ViewParams,
    /// Sphere radius and range check, world units.
    pub radius: f32,
    /// The range check's distance, world units.
    pub range: f32,
    /// Pixel of the visible viewport's top-left corner: the rotation tile starts there.
    pub noise_origin: [i32; 2],
}

/// The raw SSAO image: the occluded fraction of the kernel at every pixel (0 on background).
pub fn ssao(nd: &NdImage, kernel: &[[f32; 3]], noise: &[[f32; 3]], params: &SsaoParams) -> Image<f32> {
    Image::from_fn(nd.width, nd.height, |x, y| ssao_pixel(nd, kernel, noise, params, x as u32, y as u32))
}

/// The occluded fraction of the kernel at pixel (x, y).
pub fn ssao_pixel(nd: &NdImage, kernel: &[[f32; 3]], noise: &[[f32; 3]], p: &SsaoParams, x: u32, y: u32) -> f32 {
    let here = nd.get(x as usize, y as usize);
    if here[0] == 0.0 && here[1] == 0.0 && here[2] == 0.0 {
        return 0.0;
    }
    let v = &p.view;
    let depth = v.linear_depth(here[3]);
    let pos = v.view_position(x, y, depth);
    let tile = |c: u32, o: i32| (c as i32 - o).rem_euclid(4) as usize;
    let r = noise[tile(y, p.noise_origin[1]) * 4 + tile(x, p.noise_origin[0])];
    let epsilon = SSAO_EPSILON * (v.far - v.near);
    let mut occluded = 0u32;
    for k in kernel {
        // reflect(k, r) = k − 2 (r · k) r
        let dot = r[0] * k[0] + r[1] * k[1] + r[2] * k[2];
        let k = [k[0] - 2.0 * dot * r[0], k[1] - 2.0 * dot * r[1], k[2] - 2.0 * dot * r[2]];
        let q = [pos[0] + p.radius * k[0], pos[1] + p.radius * k[1], pos[2] + p.radius * k[2]];
        let q_depth = -q[2];
        if q_depth <= 0.0 {
            continue;
        }
        let t = v.project(q);
        let tx = t[0].floor().clamp(0.0, (nd.width - 1) as f32) as usize;
        let ty = t[1].floor().clamp(0.0, (nd.height - 1) as f32) as usize;
        let surface = v.linear_depth(nd.get(tx, ty)[3]);
        let diff = q_depth - surface;
        if diff > epsilon && diff < p.range {
            occluded += 1;
        }
    }
    occluded as f32 / kernel.len() as f32
}

/// The matching 4 × 4 blur: the mean over the window x−2..=x+1, y−2..=y+1 (every rotation of
/// the tile exactly once) of the geometry pixels in it; background stays 0.
pub fn ssao_blur(nd: &NdImage, raw: &Image<f32>) -> Image<f32> {
    let geometry = |x: usize, y: usize| {
        let n = nd.get(x, y);
        !(n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0)
    };
    Image::from_fn(raw.width, raw.height, |x, y| {
        if !geometry(x, y) {
            return 0.0;
        }
        let (mut sum, mut count) = (0.0f32, 0u32);
        for dy in -2i64..=1 {
            for dx in -2i64..=1 {
                let (sx, sy) = (x as i64 + dx, y as i64 + dy);
                if sx < 0 || sy < 0 || sx >= raw.width as i64 || sy >= raw.height as i64 {
                    continue;
                }
                if geometry(sx as usize, sy as usize) {
                    sum += raw.get(sx as usize, sy as usize);
                    count += 1;
                }
            }
        }
        sum / count as f32
    })
}

/// Crytek SSAO's frame on the CPU before its blur ([`crate::verify::reference_ao`]): its kernel
/// and rotation tile from the settings, level 0 read back; a bound of two flipped samples.
pub(crate) fn of_frame(inputs: &FrameInputs) -> Result<ReferenceAo, crate::Error> {
    let (settings, view) = (&inputs.settings.ssao, inputs.view);
    let params = SsaoParams {
        view: ViewParams::of(view),
        radius: settings.radius_world,
        range: settings.range_world,
        noise_origin: [view.guard as i32; 2],
    };
    let points = settings.kernel_points();
    if points.len() != settings.samples as usize {
        return Err(crate::Error::out_of_range("ssao-samples", settings.samples, "a kernel's sample count"));
    }
    let cpu = ssao(&inputs.nd[0], &points, &crate::noise::ssao_noise(settings.noise_seed), &params);
    Ok(ReferenceAo { ao: cpu, every_pixel_bound: 2.0 / settings.samples as f32 })
}
