//! CPU reference of VO area sampling: the moments pyramid (`moments.wgsl`) and the
//! pass (`vo_area.wgsl`), in the shaders' f32 operation order.

use crate::image::{Image, NdImage};
use crate::method::vo_line::reference::{
    VoParams, tangent_plane_depth, vo_ao, vo_chord_half, vo_pixel, vo_reflect, vo_sample,
};
use crate::reference::binomial_5x5;
use crate::view_params::ViewParams;

/// A level of the moments pyramid: (E\[z\], E\[z²\]) of linear depth, world units.
pub type MomentsImage = Image<[f32; 2]>;

pub use crate::sample_sets::vo_sigma_floor;

/// The moments pyramid over the ND map `nd0`: level 0 = (z, z²), z = −z_view at each pixel;
/// level l the binomial 5 × 5 of level l − 1 around (2x, 2y), ⌊W/2⌋ × ⌊H/2⌋ (at least 1),
/// until 1 × 1 — the GPU texture's mip chain.
pub fn moments_pyramid(nd0: &NdImage, view: &ViewParams) -> Vec<MomentsImage> {
    let level0 = Image {
        width: nd0.width,
        height: nd0.height,
        data: nd0
            .data
            .iter()
            .map(|t| {
                let z = view.linear_depth(t[3]);
                [z, z * z]
            })
            .collect(),
    };
    let mut levels = vec![level0];
    loop {
        let src = levels.last().expect("level 0 exists");
        if src.width == 1 && src.height == 1 {
            return levels;
        }
        let next = Image::from_fn((src.width / 2).max(1), (src.height / 2).max(1), |x, y| {
            binomial_5x5(src, [2 * x as i64, 2 * y as i64])
        });
        levels.push(next);
    }
}

/// Bilinear read of level `l` at `at` (level-0 pixels; texel x of level l centred on level-0
/// pixel 2^l x), clamp-to-edge.
fn moments_bilinear(levels: &[MomentsImage], at: [f32; 2], l: usize) -> [f32; 2] {
    let level = &levels[l];
    let k = (-(l as f32)).exp2();
    let u = [at[0] * k, at[1] * k];
    let base = [u[0].floor(), u[1].floor()];
    let f = [u[0] - base[0], u[1] - base[1]];
    let (bx, by) = (base[0] as i64, base[1] as i64);
    let m00 = level.clamped(bx, by);
    let m10 = level.clamped(bx + 1, by);
    let m01 = level.clamped(bx, by + 1);
    let m11 = level.clamped(bx + 1, by + 1);
    let lerp = |a: [f32; 2], b: [f32; 2], t: f32| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
    lerp(lerp(m00, m10, f[0]), lerp(m01, m11, f[0]), f[1])
}

/// Trilinear read at level of detail `lod`, clamped to the pyramid.
pub fn moments_trilinear(levels: &[MomentsImage], at: [f32; 2], lod: f32) -> [f32; 2] {
    let l = lod.clamp(0.0, (levels.len() - 1) as f32);
    let level = l.floor();
    let t = l - level;
    let fine = moments_bilinear(levels, at, level as usize);
    if t <= 0.0 {
        return fine;
    }
    let coarse = moments_bilinear(levels, at, level as usize + 1);
    [fine[0] + (coarse[0] - fine[0]) * t, fine[1] + (coarse[1] - fine[1]) * t]
}

/// VO with area samples at every pixel. `samples`: (x, y, A_i); `lod_offsets`: ½ log2(π A_i/ΣA)
/// (`crate::sample_sets::vo_area_lod_offsets`).
pub fn vo_area(
    nd: &NdImage,
    zoom: &Image<f32>,
    moments: &[MomentsImage],
    samples: &[[f32; 3]],
    lod_offsets: &[f32],
    noise: &[[f32; 2]],
    p: &VoParams,
) -> Image<f32> {
    let floor = vo_sigma_floor(p.view.near, p.view.far);
    Image::from_fn(nd.width, nd.height, |x, y| {
        let (x, y) = (x as u32, y as u32);
        let here = nd.get(x as usize, y as usize);
        let n = [here[0], here[1], here[2]];
        vo_pixel(nd, zoom, noise, p, (x, y), |depth, z, u, radius| {
            let position = p.view.view_position(x, y, depth);
            let scale = radius * z / p.zoom_unit;
            let thickness = p.thickness / radius;
            let lod_sphere = scale.log2();
            let (mut free, mut allowed) = (0.0f32, 0.0f32);
            for (sample, offset) in samples.iter().zip(lod_offsets) {
                let s = vo_reflect([sample[0], sample[1]], u);
                let at = [x as f32 + s[0] * scale, y as f32 - s[1] * scale];
                let m = moments_trilinear(moments, at, lod_sphere + offset);
                // E[z²] − E[z]² cancels: fused like the multiply-add the GPU compiles it to, so that
                // both round the product once.
                let mut sigma = (-m[0]).mul_add(m[0], m[1]).max(0.0).sqrt();
                if sigma < floor {
                    sigma = 0.0;
                }
                let mu = (m[0] - depth) / radius;
                let z_s = vo_chord_half(s[0], s[1]);
                let mut chord = (-z_s, z_s);
                if p.normal_clamp {
                    // Where the sample's own view ray crosses the tangent plane (vo_line's doc).
                    let cut = tangent_plane_depth(&p.view, position, n, [at[0] + 0.5, at[1] + 0.5]);
                    chord.1 = z_s.min((cut - depth) / radius);
                }
                let (f, a) = vo_sample(chord, mu, sigma / radius, thickness);
                free += sample[2] * f;
                allowed += sample[2] * a;
            }
            vo_ao(free, allowed)
        })
    })
}
