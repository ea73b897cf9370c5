//! CPU reference of Volumetric Obscurance with line samples (`shaders/vo_line.wgsl`), in the
//! shader's f32 operation order.

use super::ssao::ViewParams;
use super::{Image, NdImage};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoParams {
    pub view: ViewParams,
    /// Sphere radius, world units; world units per zoom unit.
    pub radius: f32,
    pub zoom_unit: f32,
    pub normal_clamp: bool,
    /// Thickness in world units, 0 = off.
    pub thickness: f32,
    /// Pixel of the visible viewport's top-left corner: the 4 × 4 tile starts there.
    pub noise_origin: [i32; 2],
}

/// The free and allowed lengths of one line sample through the unit sphere at disk point
/// (x, y): the chord is [−z_s, z_s] (z_d away from the camera), occupied behind the surface
/// at d_r (and free again past d_r + thickness with the thickness model); the normal clamp keeps
/// the part above the tangent plane n_x x + n_y y − n_z z_d ≥ 0.
pub fn vo_line_sample(s: [f32; 2], d_r: f32, n: [f32; 3], clamp: bool, thickness: f32) -> (f32, f32) {
    let z_s = (1.0 - (s[0] * s[0] + s[1] * s[1])).max(0.0).sqrt();
    let mut lo = -z_s;
    let mut hi = z_s;
    if clamp {
        let c = n[0] * s[0] + n[1] * s[1];
        if n[2].abs() < 1e-6 {
            if c < 0.0 {
                hi = lo;
            }
        } else if n[2] > 0.0 {
            hi = hi.min(c / n[2]);
        } else {
            lo = lo.max(c / n[2]);
        }
    }
    let allowed = (hi - lo).max(0.0);
    let mut free = (hi.min(d_r) - lo).max(0.0);
    if thickness > 0.0 {
        free += (hi - lo.max(d_r + thickness)).max(0.0);
    }
    (free.min(allowed), allowed)
}

/// VO at every pixel: ao = 1 − Σ A_i free_i / Σ A_i allowed_i (0 on background and where no
/// sample has an allowed part).
pub fn vo_line(nd: &NdImage, zoom: &Image<f32>, samples: &[[f32; 3]], noise: &[[f32; 2]], p: &VoParams) -> Image<f32> {
    Image::from_fn(nd.width, nd.height, |x, y| vo_line_pixel(nd, zoom, samples, noise, p, x as u32, y as u32))
}

pub fn vo_line_pixel(
    nd: &NdImage,
    zoom: &Image<f32>,
    samples: &[[f32; 3]],
    noise: &[[f32; 2]],
    p: &VoParams,
    x: u32,
    y: u32,
) -> f32 {
    let here = nd.get(x as usize, y as usize);
    if here[0] == 0.0 && here[1] == 0.0 && here[2] == 0.0 {
        return 0.0;
    }
    let v = &p.view;
    let depth = v.linear_depth(here[3]);
    let scale = p.radius * zoom.get(x as usize, y as usize) / p.zoom_unit;
    let tile = |c: u32, o: i32| (c as i32 - o).rem_euclid(4) as usize;
    let u = noise[tile(y, p.noise_origin[1]) * 4 + tile(x, p.noise_origin[0])];
    let thickness = p.thickness / p.radius;
    let (mut free, mut allowed) = (0.0f32, 0.0f32);
    for sample in samples {
        // Reflection about the line through u: s' = 2 (s · u) u − s.
        let dot = sample[0] * u[0] + sample[1] * u[1];
        let s = [2.0 * dot * u[0] - sample[0], 2.0 * dot * u[1] - sample[1]];
        let tx = (x as f32 + 0.5 + s[0] * scale).floor().clamp(0.0, (nd.width - 1) as f32) as usize;
        let ty = (y as f32 + 0.5 - s[1] * scale).floor().clamp(0.0, (nd.height - 1) as f32) as usize;
        let d_r = (v.linear_depth(nd.get(tx, ty)[3]) - depth) / p.radius;
        let (f, a) = vo_line_sample(s, d_r, [here[0], here[1], here[2]], p.normal_clamp, thickness);
        free += sample[2] * f;
        allowed += sample[2] * a;
    }
    if allowed > 0.0 { 1.0 - free / allowed } else { 0.0 }
}
