//! CPU reference of Volumetric Obscurance with line samples (`vo_line.wgsl`) and of
//! what VO's line and area sampling share (`shaders/shared/vo.wgsl`), in the shaders' f32
//! operation order.

use super::settings::{VoCombine, VoSettings};
use crate::camera::FrameView;
use crate::image::{Image, NdImage};
use crate::view_params::ViewParams;

#[derive(Clone, Copy, Debug, PartialEq)]
/// Every number VO with line samples reads besides the images, the samples and the noise.
pub struct VoParams {
    /// The view's depth range and projection.
    pub view: ViewParams,
    /// Sphere radius, world units; world units per zoom unit.
    pub radius: f32,
    /// A second radius, combined with the first by `combine`.
    pub radius2: Option<f32>,
    /// How two radii combine.
    pub combine: VoCombine,
    /// World units per zoom unit.
    pub zoom_unit: f32,
    /// Whether the normal clamp cuts the chords.
    pub normal_clamp: bool,
    /// Thickness in world units, 0 = off.
    pub thickness: f32,
    /// Pixel of the visible viewport's top-left corner: the 4 × 4 tile starts there.
    pub noise_origin: [i32; 2],
}

impl VoParams {
    /// The parameters the VO passes use for `view` (guard band `guard`) and `settings`.
    pub fn of(view: &FrameView, settings: &VoSettings, guard: u32) -> VoParams {
        VoParams {
            view: ViewParams::of(view),
            radius: settings.radius_world,
            radius2: settings.radius2_world,
            combine: settings.combine,
            zoom_unit: view.zoom_unit,
            normal_clamp: settings.normal_clamp,
            thickness: settings.thickness_world,
            noise_origin: {
                let [x0, y0] = view.origin();
                [guard as i32 - x0 as i32, guard as i32 - y0 as i32]
            },
        }
    }
}

pub use crate::sample_sets::vo_chord_half;

/// g = n.xy / n_z of the tangent plane, whose depth at s is s · g; 0 when n_z is 0.
pub fn vo_plane(n: [f32; 3]) -> [f32; 2] {
    if n[2].abs() >= 1e-6 { [n[0] / n[2], n[1] / n[2]] } else { [0.0, 0.0] }
}

/// The allowed part (lo, hi) of the chord at disk point s (half length z_s): [−z_s, z_s], or
/// with the normal clamp the part above the tangent plane n_x x + n_y y − n_z z_d ≥ 0, at depth
/// s · g (`g` from [`vo_plane`]). Empty when hi ≤ lo. This is the paper's form, exact where
/// rays are parallel (orthographic); the passes cut each chord along the sample's own view ray
/// (`tangent_plane_depth` in this module), which perspective needs.
pub fn vo_chord(s: [f32; 2], z_s: f32, n: [f32; 3], g: [f32; 2], clamp: bool) -> (f32, f32) {
    let (mut lo, mut hi) = (-z_s, z_s);
    if clamp {
        if n[2].abs() < 1e-6 {
            if n[0] * s[0] + n[1] * s[1] < 0.0 {
                hi = lo;
            }
        } else if n[2] > 0.0 {
            hi = hi.min(s[0] * g[0] + s[1] * g[1]);
        } else {
            lo = lo.max(s[0] * g[0] + s[1] * g[1]);
        }
    }
    (lo, hi)
}

/// ∫ from lo to hi of the chance that z_d lies in front of a surface whose depth is a box
/// over μ ± σ (§4.2): the constant part up to μ − σ and the linear part (z1 − z0)(μ + σ −
/// (z0 + z1)/2)/(2σ) over [z0, z1] = [μ − σ, μ + σ] ∩ [lo, hi]. σ = 0: a step at μ.
pub fn vo_visible(lo: f32, hi: f32, mu: f32, sigma: f32) -> f32 {
    let mut free = (hi.min(mu - sigma) - lo).max(0.0);
    if sigma > 0.0 {
        let z0 = (mu - sigma).max(lo).min(hi);
        let z1 = (mu + sigma).max(lo).min(hi);
        free += (z1 - z0) * (mu + sigma - 0.5 * (z0 + z1)) / (2.0 * sigma);
    }
    free
}

/// The free and allowed lengths of the chord (lo, hi) for a surface at μ ± σ, with the
/// thickness model (in units of the radius, 0 = off) adding the part behind the surface's back
/// face.
pub fn vo_sample((lo, hi): (f32, f32), mu: f32, sigma: f32, thickness: f32) -> (f32, f32) {
    if hi <= lo {
        return (0.0, 0.0);
    }
    let allowed = hi - lo;
    let mut free = vo_visible(lo, hi, mu, sigma);
    if thickness > 0.0 {
        free += allowed - vo_visible(lo - thickness, hi - thickness, mu, sigma);
    }
    (free.min(allowed), allowed)
}

/// The normal clamp's cut: the linear depth at which the view ray through screen position `c`
/// (pixels from the frame's corner; a texel's centre is t + 0.5) crosses the plane through `p`
/// with normal `n` (facing the eye); huge where the ray stays on the eye's side ahead of it
/// (`shaders/shared/vo.wgsl`).
pub fn tangent_plane_depth(view: &ViewParams, p: [f32; 3], n: [f32; 3], c: [f32; 2]) -> f32 {
    let s = [(c[0] - view.center[0]) / view.f_px, (view.center[1] - c[1]) / view.f_px];
    let np = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
    if view.orthographic {
        let side = n[0] * s[0] + n[1] * s[1] - np;
        if n[2].abs() < 1e-12 {
            return if side > 0.0 { 3.0e38 } else { -3.0e38 };
        }
        return side / n[2];
    }
    let nr = n[0] * s[0] + n[1] * s[1] - n[2];
    if nr < 0.0 { np / nr } else { 3.0e38 }
}

/// A line sample: the chord at s against the visible surface at d_r (§4.1, σ = 0).
pub fn vo_line_sample(s: [f32; 2], d_r: f32, n: [f32; 3], clamp: bool, thickness: f32) -> (f32, f32) {
    let chord = vo_chord(s, vo_chord_half(s[0], s[1]), n, vo_plane(n), clamp);
    vo_sample(chord, d_r, 0.0, thickness)
}

/// Two radii (Fig. 8): brightness multiplies, or the darker one.
pub fn vo_combine(small: f32, large: f32, combine: VoCombine) -> f32 {
    match combine {
        VoCombine::Product => 1.0 - (1.0 - small) * (1.0 - large),
        VoCombine::Min => small.max(large),
    }
}

/// A disk sample reflected about the line through the unit 2D direction u: s' = 2 (s · u) u − s.
pub fn vo_reflect(sample: [f32; 2], u: [f32; 2]) -> [f32; 2] {
    let d = sample[0] * u[0] + sample[1] * u[1];
    [2.0 * d * u[0] - sample[0], 2.0 * d * u[1] - sample[1]]
}

/// What a VO pixel shares between line and area sampling: 0 on background; otherwise
/// `obscurance(depth, zoom, u, radius)` at the first radius, combined with the second.
pub(crate) fn vo_pixel(
    nd: &NdImage,
    zoom: &Image<f32>,
    noise: &[[f32; 2]],
    p: &VoParams,
    (x, y): (u32, u32),
    obscurance: impl Fn(f32, f32, [f32; 2], f32) -> f32,
) -> f32 {
    let here = nd.get(x as usize, y as usize);
    if here[0] == 0.0 && here[1] == 0.0 && here[2] == 0.0 {
        return 0.0;
    }
    let depth = p.view.linear_depth(here[3]);
    let z = zoom.get(x as usize, y as usize);
    let tile = |c: u32, o: i32| (c as i32 - o).rem_euclid(4) as usize;
    let u = noise[tile(y, p.noise_origin[1]) * 4 + tile(x, p.noise_origin[0])];
    let ao = obscurance(depth, z, u, p.radius);
    match p.radius2 {
        Some(r2) => vo_combine(ao, obscurance(depth, z, u, r2), p.combine),
        None => ao,
    }
}

/// ao = 1 − Σ A_i free_i / Σ A_i allowed_i; 0 when nothing is allowed.
pub(crate) fn vo_ao(free: f32, allowed: f32) -> f32 {
    if allowed > 0.0 { 1.0 - free / allowed } else { 0.0 }
}

/// VO with line samples at every pixel.
pub fn vo_line(nd: &NdImage, zoom: &Image<f32>, samples: &[[f32; 3]], noise: &[[f32; 2]], p: &VoParams) -> Image<f32> {
    Image::from_fn(nd.width, nd.height, |x, y| vo_line_pixel(nd, zoom, samples, noise, p, x as u32, y as u32))
}

/// VO's occlusion at pixel (x, y).
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
    let n = [here[0], here[1], here[2]];
    vo_pixel(nd, zoom, noise, p, (x, y), |depth, z, u, radius| {
        let at = p.view.view_position(x, y, depth);
        let scale = radius * z / p.zoom_unit;
        let thickness = p.thickness / radius;
        let d_scale = (p.view.far - p.view.near) / radius;
        let d_offset = (p.view.near - depth) / radius;
        let (mut free, mut allowed) = (0.0f32, 0.0f32);
        for sample in samples {
            let s = vo_reflect([sample[0], sample[1]], u);
            let tx = (x as f32 + 0.5 + s[0] * scale).floor().clamp(0.0, (nd.width - 1) as f32) as usize;
            let ty = (y as f32 + 0.5 - s[1] * scale).floor().clamp(0.0, (nd.height - 1) as f32) as usize;
            let d_r = nd.get(tx, ty)[3] * d_scale + d_offset;
            // At the centre of the texel read (the shader's doc).
            let s_t = [(tx as f32 - x as f32) / scale.max(1e-20), (y as f32 - ty as f32) / scale.max(1e-20)];
            let z_s = vo_chord_half(s_t[0], s_t[1]);
            let mut chord = (-z_s, z_s);
            if p.normal_clamp {
                chord.1 =
                    z_s.min((tangent_plane_depth(&p.view, at, n, [tx as f32 + 0.5, ty as f32 + 0.5]) - depth) / radius);
            }
            let (f, a) = vo_sample(chord, d_r, 0.0, thickness);
            free += sample[2] * f;
            allowed += sample[2] * a;
        }
        vo_ao(free, allowed)
    })
}
