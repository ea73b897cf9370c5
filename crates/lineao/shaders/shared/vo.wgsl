// Volumetric Obscurance in the unit sphere's coordinates (Loos & Sloan §4, docs/reference.md "VO"),
// shared by line and area sampling. x right, y up, z_d away from the camera, all over the
// sphere's radius R; a disk point s is the vertical chord [−z_s, z_s], z_s = √(1 − |s|²).
#import shared/view.wgsl

// Keep in sync with `lineao::method::vo_line::VoUniform`.
struct VoUniform {
    view: ViewParams,
    noise_origin: vec2<i32>,
    // Sphere radii in world units; the second only with RADII = 2.
    radius: vec2<f32>,
    zoom_unit: f32,
    // World units; 0 = off.
    thickness: f32,
    normal_clamp: u32,
    // Two radii: 0 = brightness multiplies, 1 = the darker one.
    combine: u32,
    // Area sampling: the deepest level of the moments pyramid, and σ (world units) below which
    // the depth distribution counts as a step (docs/reference.md: 1e-3 (far − near)).
    max_level: f32,
    sigma_floor: f32,
    // The number of samples in the tables. A uniform, not an override constant: with a constant
    // count the loop is unrolled, and llvmpipe ran the unrolled loop 1.3x slower (every texel
    // fetch in flight at once; `lineao bench`, vo-line-5 32.4 -> 25.4 ms at 1280 x 1024).
    samples: u32,
    _pad: u32,
}

// The normal clamp (§4.4) keeps the part of a chord in front of P's tangent plane (through `p`,
// view space, with normal `n` facing the eye). A sample reads the depth along its own view ray,
// so the chord is cut where that ray crosses the plane: this is the plane's linear depth along
// the ray through screen position `c` (pixels from the frame's corner; a texel's centre is
// t + 0.5), or a huge value where the ray stays on the eye's side of it. Not at s · n.xy / n_z,
// the paper's depth of the plane at s, which holds only where rays are parallel
// (orthographic): in perspective, off the optical axis and at grazing angles that plane lay up
// to half a radius behind the surface, and open ground darkened.
fn tangent_plane_depth(v: ViewParams, p: vec3<f32>, n: vec3<f32>, c: vec2<f32>) -> f32 {
    let s = vec2<f32>(c.x - v.center.x, v.center.y - c.y) / v.f_px;
    let np = dot(n, p);
    if v.orthographic != 0u {
        let side = dot(n.xy, s) - np;
        if abs(n.z) < 1e-12 {
            return select(-3.0e38, 3.0e38, side > 0.0);
        }
        return side / n.z;
    }
    let nr = dot(n, vec3<f32>(s, -1.0));
    return select(3.0e38, np / nr, nr < 0.0);
}

// ∫ from lo to hi (lo < hi) of the chance that z_d lies in front of the visible surface, whose
// depth is a box distribution over μ ± σ (§4.2, Fig. 3): the constant part up to μ − σ plus the
// linear part a z + b, a = −1/(2σ), b = −a(μ + σ), over [z0, z1] = [μ − σ, μ + σ] ∩ [lo, hi],
// written as (z1 − z0)(μ + σ − (z0 + z1)/2)/(2σ). σ = 0 is a step at μ: the line sample
// max(min(z_s, d_r) + z_s, 0) of §4.1.
fn vo_visible(lo: f32, hi: f32, mu: f32, sigma: f32) -> f32 {
    let free = max(min(hi, mu - sigma) - lo, 0.0);
    // Without a branch on σ (it varies between pixels): at σ = 0, z1 = z0 and the term is 0.
    let z0 = min(max(mu - sigma, lo), hi);
    let z1 = min(max(mu + sigma, lo), hi);
    let linear = (z1 - z0) * (mu + sigma - 0.5 * (z0 + z1)) / max(2.0 * sigma, 1e-30);
    return free + select(0.0, linear, sigma > 0.0);
}

// (free, allowed) lengths of the chord at s for a surface at μ ± σ; with the thickness model
// (§4.3, `thickness` > 0, in units of R) the chord is free again behind the surface's back face:
// the integral once more, of 1 − visibility shifted back by the thickness, summed.
fn vo_sample(chord: vec2<f32>, mu: f32, sigma: f32, thickness: f32) -> vec2<f32> {
    let lo = chord.x;
    let hi = chord.y;
    // An empty chord (hi ≤ lo) gives (0, 0) through the clamps, without a branch.
    let allowed = max(hi - lo, 0.0);
    var free = vo_visible(lo, hi, mu, sigma);
    if thickness > 0.0 {
        free += allowed - vo_visible(lo - thickness, hi - thickness, mu, sigma);
    }
    return vec2<f32>(min(free, allowed), allowed);
}

// ao = 1 − Σ A_i free_i / Σ A_i allowed_i from the weighted sums; 0 when nothing is allowed.
fn vo_ao(sums: vec2<f32>) -> f32 {
    return select(0.0, 1.0 - sums.x / sums.y, sums.y > 0.0);
}

// Two radii (VO paper Fig. 8): brightness multiplies, or the darker one.
fn vo_combine(small: f32, large: f32, combine: u32) -> f32 {
    if combine == 0u {
        return 1.0 - (1.0 - small) * (1.0 - large);
    }
    return max(small, large);
}

// A disk sample (x, y) reflected about the line through the unit 2D direction u (§4.5): it
// keeps |s|, so the chord and the weight stay valid.
fn vo_reflect(sample: vec2<f32>, u: vec2<f32>) -> vec2<f32> {
    let d = sample.x * u.x + sample.y * u.y;
    return vec2<f32>(2.0 * d * u.x - sample.x, 2.0 * d * u.y - sample.y);
}

// The 2D direction of `pixel` from the 4 x 4 tile in `tile` (entries 16..32 of the tables).
fn vo_tile_index(pixel: vec2<u32>, origin: vec2<i32>) -> u32 {
    let t = ((vec2<i32>(pixel) - origin) % 4 + 4) % 4;
    return u32(16 + t.y * 4 + t.x);
}
