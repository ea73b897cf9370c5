//! CPU reference of LineAO, variants `paper` (docs/reference.md "LineAO") and `reference` (the
//! authors' shader, [`crate::method::line_ao`]), written plainly from the equations: the shader
//! `line_ao.wgsl` is optimized differently and the tests compare the two.

use glam::Vec3;

use super::{LineAoOuter, LineAoVariant};
use crate::camera::FrameView;
use crate::image::{Image, NdImage};
use crate::lighting::Light;
use crate::reference::level_texel;
use crate::settings::ChainSettings;
use crate::verify::{FrameInputs, ReferenceAo};

/// Every number LineAO reads besides the images and the noise.
#[derive(Clone, Debug, PartialEq)]
pub struct LineAoParams {
    /// `paper` or `reference`.
    pub variant: LineAoVariant,
    /// Hemispheres j ≥ 1 at full resolution or at their level's (docs/reference.md `outer`).
    pub outer: LineAoOuter,
    /// s_r: hemispheres and pyramid levels.
    pub s_r: u32,
    /// s_h: samples on the first hemisphere.
    pub s_h: u32,
    /// r0 in pixels.
    pub r0_px: f32,
    /// Tubes (Eq. 16): r0(P) = r0_px + r0_zoom · z(P).
    pub r0_zoom: f32,
    /// δ0 in normalized depth.
    pub delta0: f32,
    /// δ(j) = delta_scale · (1 − j/s_r)².
    pub delta_scale: f32,
    /// ε: occluded iff Δd > ε.
    pub epsilon: f32,
    /// Whether g_light weighs the samples.
    pub light_attenuation: bool,
    /// Unit view-space directions toward the lights, with intensities.
    pub lights: Vec<Light>,
    /// Diffuse coefficient kd.
    pub kd: f32,
    /// Specular coefficient ks.
    pub ks: f32,
    /// Specular exponent α.
    pub shininess: f32,
    /// Pixel coordinate of the visible viewport's top-left corner (the guard band).
    pub noise_origin: [i32; 2],
    /// Variant `reference`: base radius per axis in pixels per unit of zoom at d = 0
    /// ([`crate::method::line_ao::reference_scale`]).
    pub reference_scale: [f32; 2],
}

impl LineAoParams {
    /// The parameters a chain with `settings` uses for `view`.
    pub fn new(settings: &ChainSettings, view: &FrameView) -> LineAoParams {
        let ao = &settings.line_ao;
        LineAoParams {
            variant: ao.variant,
            outer: ao.outer,
            reference_scale: crate::method::line_ao::reference_scale(view, ao.reference_radius_px),
            s_r: ao.s_r,
            s_h: ao.s_h,
            r0_px: settings.r0().px,
            r0_zoom: settings.r0().per_zoom,
            delta0: ao.delta0,
            delta_scale: ao.delta_scale,
            epsilon: ao.epsilon,
            light_attenuation: ao.light_attenuation,
            lights: settings.lighting.normalized(),
            kd: settings.lighting.kd,
            ks: settings.lighting.ks,
            shininess: settings.lighting.shininess,
            noise_origin: view.noise_origin(),
        }
    }
}

/// Hermite h(x) = 3x² − 2x³ (Eq. 13), evaluated as in the shader.
pub fn hermite(x: f32) -> f32 {
    x * x * (3.0 - 2.0 * x)
}

/// δ(j) = scale · (1 − j/s_r)² (Eq. 11; the paper's scale is 1).
pub fn delta(j: u32, s_r: u32, scale: f32) -> f32 {
    let falloff = 1.0 - j as f32 / s_r as f32;
    scale * falloff * falloff
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

pub use crate::lighting::{whole_exponent, whole_pow};

/// The specular power of g_light as the shader takes it: by squaring for a whole shininess.
fn specular_pow(x: f32, alpha: f32) -> f32 {
    match whole_exponent(alpha) {
        0 => clamped_pow(x, alpha),
        n => whole_pow(x, n),
    }
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
        reflected += light.intensity * (p.kd * n.dot(light.dir).max(0.0) + p.ks * specular_pow(n_h, p.shininess));
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

/// LineAO at full-resolution pixel (x, y) in the variant `p.variant`, `outer = full`.
/// `levels` is the ND pyramid (only level 0 is read by `reference`), `zoom` the zoom map
/// (level-0 size), `noise` R1 (64 × 64) and `samples` R2 (`s_r × s_h`, zero-padded).
pub fn line_ao_pixel(
    levels: &[NdImage],
    zoom: &Image<f32>,
    noise: &[[f32; 3]],
    samples: &[[f32; 3]],
    p: &LineAoParams,
    x: usize,
    y: usize,
) -> f32 {
    let inputs = Inputs { levels, zoom, noise, samples };
    match p.variant {
        LineAoVariant::Paper => paper_pixel(&inputs, p, x, y),
        LineAoVariant::Reference => reference_pixel(&inputs, p, x, y),
    }
}

/// What both variants read besides their parameters.
struct Inputs<'a> {
    levels: &'a [NdImage],
    zoom: &'a Image<f32>,
    noise: &'a [[f32; 3]],
    samples: &'a [[f32; 3]],
}

/// R1 at pixel (x, y): the tile indexed relative to the visible viewport's corner.
fn r1_at(noise: &[[f32; 3]], p: &LineAoParams, x: usize, y: usize) -> Vec3 {
    let tile_x = (x as i32 - p.noise_origin[0]).rem_euclid(64) as usize;
    let tile_y = (y as i32 - p.noise_origin[1]).rem_euclid(64) as usize;
    vec3(noise[tile_y * 64 + tile_x])
}

fn is_background(nd: [f32; 4]) -> bool {
    nd[0] == 0.0 && nd[1] == 0.0 && nd[2] == 0.0
}

/// Variant `paper`, `outer = full`: the sum over hemispheres, clamped to [0, 1].
fn paper_pixel(inputs: &Inputs, p: &LineAoParams, x: usize, y: usize) -> f32 {
    if is_background(inputs.levels[0].get(x, y)) {
        return 0.0;
    }
    let ao: f32 = (0..p.s_r).map(|j| hemisphere(inputs, p, j, [x as u32, y as u32])).sum();
    ao.clamp(0.0, 1.0)
}

/// AO_j(P) of Eq. 6 at full-resolution pixel P on pyramid level j.
fn hemisphere(&Inputs { levels, zoom, noise, samples }: &Inputs, p: &LineAoParams, j: u32, pixel: [u32; 2]) -> f32 {
    let (w0, h0) = (levels[0].width, levels[0].height);
    let (x, y) = (pixel[0] as usize, pixel[1] as usize);
    let r1 = r1_at(noise, p, x, y);
    let level = &levels[j as usize];
    let scale = [level.width as f32 / w0 as f32, level.height as f32 / h0 as f32];
    let size = [level.width, level.height];
    let [cx, cy] = level_texel(pixel, [0.0, 0.0], scale, size);
    let centre = level.clamped(cx, cy);
    let n = Vec3::new(centre[0], centre[1], centre[2]);
    let radius = p.r0_px + (p.r0_zoom + j as f32) * zoom.get(x, y);
    let delta_j = delta(j, p.s_r, p.delta_scale);
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
    occlusion / count as f32
}

/// The full-resolution pixel that stands for texel `t` of a level `size_j` of `size_0`:
/// ⌊(t + ½) · size_0 / size_j⌋ in integers, whose nearest texel on the level is `t` again.
pub fn representative_pixel(t: usize, size_j: usize, size_0: usize) -> usize {
    ((2 * t + 1) * size_0 / (2 * size_j)).min(size_0 - 1)
}

/// `outer = level`: hemisphere j ≥ 1 at every texel of level j, evaluated exactly as `outer =
/// full` evaluates it at the texel's representative pixel (same centre texel, noise, zoom and
/// radius), so the level image is the full image subsampled; texels with a background centre
/// get 0. Each texel holds (AO_j, d_j) for the depth-aware upsampling ([`upsample_outer`]).
fn outer_level(inputs: &Inputs, p: &LineAoParams, j: u32) -> Image<[f32; 2]> {
    let (level, base) = (&inputs.levels[j as usize], &inputs.levels[0]);
    Image::from_fn(level.width, level.height, |tx, ty| {
        let centre = level.get(tx, ty);
        if is_background(centre) {
            return [0.0, centre[3]];
        }
        let pixel = [
            representative_pixel(tx, level.width, base.width) as u32,
            representative_pixel(ty, level.height, base.height) as u32,
        ];
        [hemisphere(inputs, p, j, pixel), centre[3]]
    })
}

pub use super::OUTER_DEPTH_TOLERANCE;

/// AO_j at full-resolution pixel (x, y) from the level image: bilinear over the four nearest
/// texels, each weight scaled by max(0, 1 − |d_j(t) − d_j(t_P)| / τ), where t_P is the texel
/// `outer = full` reads the centre from (so it always contributes).
pub fn upsample_outer(outer: &Image<[f32; 2]>, size_0: [usize; 2], x: usize, y: usize) -> f32 {
    let scale = [outer.width as f32 / size_0[0] as f32, outer.height as f32 / size_0[1] as f32];
    let [rx, ry] = level_texel([x as u32, y as u32], [0.0, 0.0], scale, [outer.width, outer.height]);
    let reference = outer.clamped(rx, ry)[1];
    let u = [(x as f32 + 0.5) * scale[0] - 0.5, (y as f32 + 0.5) * scale[1] - 0.5];
    let base = [u[0].floor(), u[1].floor()];
    let f = [u[0] - base[0], u[1] - base[1]];
    let (mut sum, mut total) = (0.0f32, 0.0f32);
    for dy in 0..2 {
        for dx in 0..2 {
            let texel = outer.clamped(base[0] as i64 + dx, base[1] as i64 + dy);
            let bilinear = (if dx == 1 { f[0] } else { 1.0 - f[0] }) * (if dy == 1 { f[1] } else { 1.0 - f[1] });
            let weight = bilinear * (1.0 - (texel[1] - reference).abs() / OUTER_DEPTH_TOLERANCE).max(0.0);
            sum += weight * texel[0];
            total += weight;
        }
    }
    if total > 0.0 { sum / total } else { outer.clamped(rx, ry)[0] }
}

/// The authors' falloff: occluded iff Δd ≥ 1e−5, also the lower edge of their smoothstep.
pub const REFERENCE_FALLOFF: f32 = 1e-5;

/// GLSL `smoothstep(e0, e1, x)` as written in its specification, also for e0 > e1 (the
/// authors' last hemisphere has e1 = 0 < e0).
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    hermite(((x - e0) / (e1 - e0)).clamp(0.0, 1.0))
}

/// Light an occluder with normal `n_o` reflects toward ω in the authors' weight: Σ over lights
/// of I · (max(n_o·L, 0) + max(n_o·normalize(L + ω), 0)^100).
pub fn occluder_light(p: &LineAoParams, n_o: Vec3, omega: Vec3) -> f32 {
    p.lights
        .iter()
        .map(|light| {
            let half_sum = light.dir + omega;
            let half_len = half_sum.length();
            let n_h = if half_len > 1e-12 { n_o.dot(half_sum) / half_len } else { 0.0 };
            light.intensity * (n_o.dot(light.dir).max(0.0) + whole_pow(n_h, 100))
        })
        .sum()
}

/// Variant `reference` at pixel (x, y) of level 0: the authors' shader.
fn reference_pixel(&Inputs { levels, zoom, noise, samples }: &Inputs, p: &LineAoParams, x: usize, y: usize) -> f32 {
    let nd = &levels[0];
    let centre = nd.get(x, y);
    let n = Vec3::new(centre[0], centre[1], centre[2]);
    if n == Vec3::ZERO {
        return 0.0;
    }
    let r1 = r1_at(noise, p, x, y);
    let (w, h) = (nd.width as f32, nd.height as f32);
    let depth_scale = zoom.get(x, y) / (1.0 - centre[3]).max(1e-6);
    let base = [p.reference_scale[0] * depth_scale, p.reference_scale[1] * depth_scale];
    let mut total = 0.0f32;
    let mut scaler = 0.0f32;
    for l in 0..p.s_r {
        // Radii 1.5, 4.0, 7.5, …: the scaler grows by 1.5 + l each hemisphere.
        scaler += 1.5 + l as f32;
        let falloff = if p.s_r > 1 { 1.0 - l as f32 / (p.s_r - 1) as f32 } else { 1.0 };
        let density = falloff * falloff;
        let (mut occlusion, mut used) = (0.0f32, 0u32);
        for i in 0..p.s_h {
            let omega = reflect(vec3(samples[(l * p.s_h + i) as usize]), r1);
            let n_omega = omega.dot(n);
            let ray = n_omega.signum() * omega * (n_omega != 0.0) as u32 as f32;
            let at_x = x as f32 + 0.5 + ray.x * (scaler * base[0]);
            let at_y = y as f32 + 0.5 - ray.y * (scaler * base[1]);
            if at_x < 0.0 || at_y < 0.0 || at_x > w || at_y > h {
                continue;
            }
            used += 1;
            let sample = nd.get((at_x.floor() as usize).min(nd.width - 1), (at_y.floor() as usize).min(nd.height - 1));
            let dd = centre[3] - sample[3];
            if dd >= REFERENCE_FALLOFF {
                let light = if p.light_attenuation {
                    n_omega.max(0.0) * occluder_light(p, Vec3::new(sample[0], sample[1], sample[2]), omega)
                } else {
                    0.0
                };
                occlusion += (1.0 - smoothstep(REFERENCE_FALLOFF, density, dd)) * (1.5 - light);
            }
        }
        if used > 0 {
            total += occlusion / used as f32;
        }
    }
    (total / p.s_r as f32).max(0.0)
}

/// LineAO over the whole (guard-banded) image; with `outer = level` (variant `paper`) from
/// hemisphere 0 at full resolution plus the upsampled level images.
pub fn line_ao(
    levels: &[NdImage],
    zoom: &Image<f32>,
    noise: &[[f32; 3]],
    samples: &[[f32; 3]],
    p: &LineAoParams,
) -> Image<f32> {
    let (w, h) = (levels[0].width, levels[0].height);
    if p.outer == LineAoOuter::Full || p.variant == LineAoVariant::Reference {
        return Image::from_fn(w, h, |x, y| line_ao_pixel(levels, zoom, noise, samples, p, x, y));
    }
    let inputs = Inputs { levels, zoom, noise, samples };
    let outer: Vec<_> = (1..p.s_r).map(|j| outer_level(&inputs, p, j)).collect();
    Image::from_fn(w, h, |x, y| {
        if is_background(levels[0].get(x, y)) {
            return 0.0;
        }
        let near = hemisphere(&inputs, p, 0, [x as u32, y as u32]);
        let far: f32 = outer.iter().map(|o| upsample_outer(o, [w, h], x, y)).sum();
        (near + far).clamp(0.0, 1.0)
    })
}

/// docs/reference.md's bound for every pixel of LineAO: two flipped samples per hemisphere, Σ_j 2/n_j.
pub fn line_ao_flip_bound(s_r: u32, s_h: u32) -> f32 {
    (0..s_r).map(|j| 2.0 / crate::noise::samples_on_hemisphere(s_h, j) as f32).sum()
}

/// The same bound for variant `reference`: two flipped samples per hemisphere, each weighing up
/// to 1.5/s_h, averaged over the s_r hemispheres: 3/s_h.
pub fn line_ao_reference_flip_bound(s_h: u32) -> f32 {
    3.0 / s_h as f32
}

/// LineAO's frame on the CPU ([`crate::verify::reference_ao`]): its noise tile and sample table
/// from the settings, the pyramid and zoom map read back, and the variant's flip bound.
pub(crate) fn of_frame(inputs: &FrameInputs) -> Result<ReferenceAo, crate::Error> {
    let ao = &inputs.settings.line_ao;
    let params = LineAoParams::new(inputs.settings, inputs.view);
    let table = super::sample_table(ao);
    let noise = crate::noise::noise_tile(ao.noise_seed);
    let every_pixel_bound = match ao.variant {
        LineAoVariant::Paper => line_ao_flip_bound(ao.s_r, ao.s_h),
        LineAoVariant::Reference => line_ao_reference_flip_bound(ao.s_h),
    };
    Ok(ReferenceAo { ao: line_ao(inputs.nd, inputs.zoom, &noise, &table, &params), every_pixel_bound })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Squaring agrees with `powf` to a few ulps for every whole exponent the shader squares, and
    /// a shininess that is not whole in 1..512 keeps `pow`.
    #[test]
    fn whole_pow_is_pow() {
        let mut worst = 0.0f32;
        for n in 1..512u32 {
            for k in 1..=64 {
                let x = 0.9 + 0.1 * k as f32 / 64.0;
                let exact = (x as f64).powi(n as i32);
                worst = worst.max(((whole_pow(x, n) as f64 - exact) / exact).abs() as f32);
            }
            assert_eq!(whole_pow(-0.5, n), 0.0);
            assert_eq!(whole_pow(0.0, n), 0.0);
        }
        assert!(worst < 2e-5, "relative error {worst}");
        assert_eq!(whole_exponent(32.0), 32);
        assert_eq!([whole_exponent(32.5), whole_exponent(0.0), whole_exponent(512.0)], [0; 3]);
    }
}
