// Volumetric Obscurance with area samples (Loos & Sloan 2010, §4.2): each disk sample stands
// for its Voronoi cell of the disk, and instead of one depth it reads the distribution of depth
// over the cell's footprint from the moments pyramid — mean μ = E[z] and σ² = E[z²] − E[z]² —
// modelled as a box over μ ± σ. The occupancy along the chord then falls off linearly instead
// of stepping, and the chord's free length is the paper's two-part integral (`vo_visible`). One
// sample (the whole disk) already darkens creases and contacts without noise.
//
// Level of detail: the footprint of sample i is π (R z(P)/zoom_unit)² A_i/ΣA pixels, so
// lod_i = log2(R z(P)/zoom_unit) + ½ log2(π A_i/ΣA): one log2 per pixel, the second term comes
// precomputed in the table's w. Reads are trilinear, by hand (the CPU reference repeats the
// arithmetic exactly; a sampler would add the hardware's 8-bit weights).
//
// The normal clamp cuts each chord where the sample's own view ray, through the sample's point
// on screen, crosses P's tangent plane (`tangent_plane_depth`), as line sampling does.
#import shared/nd.wgsl
#import shared/vo_pass.wgsl
#import moments_layout.wgsl

// The tables' w: ½ log2(π A_i/ΣA), each sample's footprint.
// The moments pyramid (`moments.wgsl`): its layout and (E[z], E[z²]) of every level.
@group(0) @binding(5) var<uniform> levels: array<vec4<u32>, MAX_MOMENT_LEVELS>;
@group(0) @binding(6) var<storage, read> moments: array<vec2<f32>>;

// Bilinear read of one level at `at`, in level-0 pixels from the corner of pixel (0, 0)'s centre:
// texel x of level l is centred on level-0 pixel 2^l x, clamp-to-edge.
fn moments_bilinear(at: vec2<f32>, level: u32) -> vec2<f32> {
    let rect = levels[level];
    let u = at * exp2(-f32(level));
    let base = floor(u);
    let f = u - base;
    let i = vec2<i32>(base);
    let m00 = moments[moments_index(rect, i)];
    let m10 = moments[moments_index(rect, i + vec2<i32>(1, 0))];
    let m01 = moments[moments_index(rect, i + vec2<i32>(0, 1))];
    let m11 = moments[moments_index(rect, i + vec2<i32>(1, 1))];
    let top = m00 + (m10 - m00) * f.x;
    let bottom = m01 + (m11 - m01) * f.x;
    return top + (bottom - top) * f.y;
}

fn moments_trilinear(at: vec2<f32>, lod: f32) -> vec2<f32> {
    let l = clamp(lod, 0.0, params.max_level);
    let level = floor(l);
    let t = l - level;
    let fine = moments_bilinear(at, u32(level));
    if t <= 0.0 {
        return fine;
    }
    return fine + (moments_bilinear(at, u32(level) + 1u) - fine) * t;
}

fn obscurance(pixel: vec2<u32>, here: vec4<f32>, depth: f32, zoom: f32, u: vec2<f32>, radius: f32) -> f32 {
    let scale = radius * zoom / params.zoom_unit;
    let thickness = params.thickness / radius;
    let lod_sphere = log2(scale);
    let clamp_on = params.normal_clamp != 0u;
    let p = view_position(params.view, pixel, depth);
    var sums = vec2<f32>(0.0);
    for (var i = 0u; i < params.samples; i++) {
        let sample = tables[i];
        let s = vo_reflect(sample.xy, u);
        let at = vec2<f32>(f32(pixel.x) + s.x * scale, f32(pixel.y) - s.y * scale);
        let m = moments_trilinear(at, lod_sphere + sample.w);
        var sigma = sqrt(max(m.y - m.x * m.x, 0.0));
        if sigma < params.sigma_floor {
            sigma = 0.0;
        }
        let mu = (m.x - depth) / radius;
        let z_s = sqrt(max(1.0 - (s.x * s.x + s.y * s.y), 0.0));
        var chord = vec2<f32>(-z_s, z_s);
        if clamp_on {
            chord.y = min(z_s, (tangent_plane_depth(params.view, p, here.xyz, at + 0.5) - depth) / radius);
        }
        sums += sample.z * vo_sample(chord, mu, sigma / radius, thickness);
    }
    return vo_ao(sums);
}
