//! CPU reference of LineAO, variant `paper` (`shaders/line_ao.wgsl`, CONTRACT.md "LineAO").

use glam::Vec3;

use super::{Image, NdImage, level_texel};
use crate::lighting::Light;
use crate::settings::ChainSettings;

/// Every number LineAO reads besides the images and the noise.
#[derive(Clone, Debug, PartialEq)]
pub struct LineAoParams {
    pub s_r: u32,
    pub s_h: u32,
    pub r0_px: f32,
    pub delta0: f32,
    pub epsilon: f32,
    pub light_attenuation: bool,
    /// Unit view-space directions toward the lights, with intensities.
    pub lights: Vec<Light>,
    pub kd: f32,
    pub ks: f32,
    pub shininess: f32,
    /// Pixel coordinate of the visible viewport's top-left corner (the guard band).
    pub noise_origin: [i32; 2],
}

impl LineAoParams {
    /// The parameters a chain with `settings` uses at guard band `guard`.
    pub fn from_settings(settings: &ChainSettings, guard: u32) -> LineAoParams {
        let ao = &settings.line_ao;
        LineAoParams {
            s_r: ao.s_r,
            s_h: ao.s_h,
            r0_px: settings.r0_px(),
            delta0: ao.delta0,
            epsilon: ao.epsilon,
            light_attenuation: ao.light_attenuation,
            lights: settings.lighting.normalized(),
            kd: settings.lighting.kd,
            ks: settings.lighting.ks,
            shininess: settings.lighting.shininess,
            noise_origin: [guard as i32; 2],
        }
    }
}

/// Hermite h(x) = 3x² − 2x³ (Eq. 13), evaluated as in the shader.
pub fn hermite(x: f32) -> f32 {
    x * x * (3.0 - 2.0 * x)
}

/// δ(j) = (1 − j/s_r)² (Eq. 11).
pub fn delta(j: u32, s_r: u32) -> f32 {
    let falloff = 1.0 - j as f32 / s_r as f32;
    falloff * falloff
}

/// g_depth (Eq. 12): 0 above δ(j), 1 below δ0, 1 − h((Δd − δ0)/(δ(j) − δ0)) between.
pub fn depth_weight(dd: f32, delta_j: f32, delta0: f32) -> f32 {
    if dd > delta_j {
        0.0
    } else if dd < delta0 {
        1.0
    } else {
        1.0 - hermite((dd - delta0) / (delta_j - delta0))
    }
}

fn clamped_pow(x: f32, alpha: f32) -> f32 {
    if x > 0.0 { x.powf(alpha) } else { 0.0 }
}

/// g_light (Eq. 14–15) for normal `n` and direction ω.
pub fn light_weight(p: &LineAoParams, n: Vec3, omega: Vec3) -> f32 {
    if !p.light_attenuation {
        return 1.0;
    }
    let mut reflected = 0.0;
    for light in &p.lights {
        let half_sum = light.dir + omega;
        let half_len = half_sum.length();
        let n_h = if half_len > 1e-12 { n.dot(half_sum) / half_len } else { 0.0 };
        reflected += light.intensity * (p.kd * n.dot(light.dir).max(0.0) + p.ks * clamped_pow(n_h, p.shininess));
    }
    1.0 - reflected.min(1.0)
}

/// WGSL `reflect(e1, e2)` = e1 − 2 · dot(e2, e1) · e2.
fn reflect(e1: Vec3, e2: Vec3) -> Vec3 {
    e1 - 2.0 * e2.dot(e1) * e2
}

fn vec3(v: [f32; 3]) -> Vec3 {
    Vec3::from_array(v)
}

/// LineAO at full-resolution pixel (x, y): the sum over hemispheres, clamped to [0, 1].
/// `levels` is the ND pyramid, `zoom` the zoom map (level-0 size), `noise` R1 (64 × 64) and
/// `samples` R2 (`s_r × s_h`).
pub fn line_ao_pixel(
    levels: &[NdImage],
    zoom: &Image<f32>,
    noise: &[[f32; 3]],
    samples: &[[f32; 3]],
    p: &LineAoParams,
    x: usize,
    y: usize,
) -> f32 {
    let centre0 = levels[0].get(x, y);
    if centre0[0] == 0.0 && centre0[1] == 0.0 && centre0[2] == 0.0 {
        return 0.0;
    }
    let (w0, h0) = (levels[0].width, levels[0].height);
    let tile_x = (x as i32 - p.noise_origin[0]).rem_euclid(64) as usize;
    let tile_y = (y as i32 - p.noise_origin[1]).rem_euclid(64) as usize;
    let r1 = vec3(noise[tile_y * 64 + tile_x]);
    let z = zoom.get(x, y);
    let pixel = [x as u32, y as u32];
    let mut ao = 0.0f32;
    for j in 0..p.s_r {
        let level = &levels[j as usize];
        let scale = [level.width as f32 / w0 as f32, level.height as f32 / h0 as f32];
        let size = [level.width, level.height];
        let [cx, cy] = level_texel(pixel, [0.0, 0.0], scale, size);
        let centre = level.clamped(cx, cy);
        let n = Vec3::new(centre[0], centre[1], centre[2]);
        let radius = p.r0_px + j as f32 * z;
        let delta_j = delta(j, p.s_r);
        let count = crate::noise::samples_on_hemisphere(p.s_h, j);
        let mut occlusion = 0.0f32;
        for i in 0..count {
            let mut omega = reflect(r1, vec3(samples[(j * p.s_h + i) as usize]));
            if omega.dot(n) < 0.0 {
                omega = -omega;
            }
            let [sx, sy] = level_texel(pixel, [omega.x * radius, -omega.y * radius], scale, size);
            let dd = centre[3] - level.clamped(sx, sy)[3];
            if dd > p.epsilon {
                occlusion += depth_weight(dd, delta_j, p.delta0) * light_weight(p, n, omega);
            }
        }
        ao += occlusion / count as f32;
    }
    ao.clamp(0.0, 1.0)
}

/// LineAO over the whole (guard-banded) image.
pub fn line_ao(
    levels: &[NdImage],
    zoom: &Image<f32>,
    noise: &[[f32; 3]],
    samples: &[[f32; 3]],
    p: &LineAoParams,
) -> Image<f32> {
    Image::from_fn(levels[0].width, levels[0].height, |x, y| line_ao_pixel(levels, zoom, noise, samples, p, x, y))
}
