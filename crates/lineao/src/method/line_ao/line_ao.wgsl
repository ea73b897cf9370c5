// LineAO (Eichelbaum et al., TVCG 2013, Eq. 7): ambient occlusion of dense lines summed over
// s_r hemispheres of growing radius, each read from its own level of the Gaussian ND pyramid.
//
//   LineAO(P) = clamp( sum_j AO_j(P), 0, 1 )                                       (Eq. 7)
//   AO_j(P)   = 1/n_j sum_i [Δd > ε] · g_depth(Δd, j) · g_light(n_j(P), ω_i)      (Eq. 6, 9)
//   Δd        = d_j(P) - d_j(P + r_j (ω.x, -ω.y))                                  (Eq. 10)
//   δ(j)      = delta_scale · (1 - j/s_r)²  (Eq. 11; the paper's delta_scale is 1)
//   n_j = ceil(s_h / (j + 1)),  r_j = r0 + j · z(P) pixels  (tubes: r0 = 1.5 · z(P) · t_s, Eq. 16)
//   ω_i = reflect(R1(P), R2[j][i]), flipped into n_j(P)'s hemisphere
//
// The occlusion test departs from Eq. 8 on purpose (Δd > ε, not Δd >= 0): see docs/reference.md.
//
// With REFERENCE the pass computes variant `reference` instead, the authors' own shader
// (`lineao::method::line_ao` documents it): `reference_ao` below.
//
// With OUTER_LEVEL (`outer = level`) hemispheres j >= 1 come from `line_ao_outer`, run before
// at level j's resolution, and are upsampled depth-aware here (`upsample_outer`).
#import shared/nd.wgsl
#import shared/lighting.wgsl

// Compile-time sample counts so that the loops can unroll (paper §3.4).
override S_R: u32 = 3u;
override S_H: u32 = 32u;
// Benchmark only (`lineao-tap-floor`): fetch every sample as LineAO does, but only sum the depths.
override TAP_FLOOR: bool = false;
// Eq. 15 on or off (`--no-light-attenuation`): a constant, so the off case costs nothing per sample.
override LIGHT_ATTENUATION: bool = true;
// Variant `reference` instead of `paper`.
override REFERENCE: bool = false;
// `outer = level`: `line_ao` reads hemispheres j >= 1 from outer1..outer4, which
// `line_ao_outer` wrote for hemisphere LEVEL.
override OUTER_LEVEL: bool = false;
override LEVEL: u32 = 1u;

// OUTER_DEPTH_TOLERANCE: Rust's `lineao::method::line_ao::OUTER_DEPTH_TOLERANCE`.
#import rust/constants.wgsl

// The authors' falloff: occluded iff Δd >= 1e-5, also the lower edge of their smoothstep.
const REFERENCE_FALLOFF: f32 = 1e-5;

// Keep in sync with `lineao::method::line_ao::LineAoUniform`.
struct LineAoUniform {
    levels: Levels,
    // Pixel coordinate of the visible viewport's top-left corner (the guard band's width).
    noise_origin: vec2<i32>,
    r0_px: f32,
    delta0: f32,
    // Variant `reference`: radius_px / z_fit * (W, H) / max(W, H).
    reference_scale: vec2<f32>,
    epsilon: f32,
    // Tubes (Eq. 16): r0(P) = r0_px + r0_zoom · z(P).
    r0_zoom: f32,
    // δ(j) = delta_scale · (1 - j/s_r)².
    delta_scale: f32,
}

@group(0) @binding(0) var<uniform> params: LineAoUniform;
@group(0) @binding(1) var<uniform> lighting: Lighting;
// R1: 64 x 64 tile of unit vectors, row-major noise[y][x].
@group(0) @binding(2) var<storage, read> noise: array<vec4<f32>>;
// R2: samples[j * S_H + i], unit vectors. A uniform array (MAX_LEVELS x 256 entries): its
// constant-indexed loads are scalar on a CPU rasterizer, which made every tap ~3x cheaper than
// from a storage buffer (measured with `lineao bench`, pass lineao-tap-floor).
@group(0) @binding(3) var<uniform> samples: array<vec4<f32>, 1280>;
@group(0) @binding(4) var zoom_map: texture_2d<f32>;
@group(0) @binding(5) var ao_out: texture_storage_2d<r32float, write>;
@group(0) @binding(6) var nd0: texture_2d<f32>;
@group(0) @binding(7) var nd1: texture_2d<f32>;
@group(0) @binding(8) var nd2: texture_2d<f32>;
@group(0) @binding(9) var nd3: texture_2d<f32>;
@group(0) @binding(10) var nd4: texture_2d<f32>;
// `outer = level`: (AO_j, d_j) at level j's resolution for j = 1..4, and line_ao_outer's output.
@group(0) @binding(11) var outer1: texture_2d<f32>;
@group(0) @binding(12) var outer2: texture_2d<f32>;
@group(0) @binding(13) var outer3: texture_2d<f32>;
@group(0) @binding(14) var outer4: texture_2d<f32>;
@group(0) @binding(15) var outer_out: texture_storage_2d<rgba32float, write>;

// Illumination-based attenuation (Eq. 14-15): 1 - min(sum over lights of the Blinn-Phong BRDF
// lit from L_s and seen from ω, 1). `n_omega` = n · ω. For unit L and ω, |L + ω|² = 2 + 2 L·ω,
// so n · normalize(L + ω) needs no normalize (this loop runs once per sample).
fn light_weight(n: vec3<f32>, omega: vec3<f32>, n_omega: f32) -> f32 {
    if (!LIGHT_ATTENUATION) {
        return 1.0;
    }
    var reflected = 0.0;
    for (var s = 0u; s < light_count(lighting); s++) {
        let light = lighting.lights[s];
        let n_l = dot(n, light.xyz);
        let sum_sq = 2.0 + 2.0 * dot(light.xyz, omega);
        let n_h = select(0.0, min((n_l + n_omega) * inverseSqrt(sum_sq), 1.0), sum_sq > 1e-12);
        reflected += light.w * (lighting.kd * max(n_l, 0.0) + lighting.ks * specular_pow(n_h, lighting.shininess));
    }
    return 1.0 - min(reflected, 1.0);
}

// AO_j(P, r0 + j z(P)) of Eq. 6 on pyramid level `nd`.
fn hemisphere(nd: texture_2d<f32>, j: u32, pixel: vec2<u32>, r1: vec3<f32>, zoom: f32) -> f32 {
    let scale = params.levels.scale[j].xy;
    let size = params.levels.size[j].xy;
    let centre = textureLoad(nd, level_texel(pixel, vec2<f32>(0.0), scale, size), 0);
    let n = centre.xyz;
    let radius = params.r0_px + (params.r0_zoom + f32(j)) * zoom;
    let falloff = 1.0 - f32(j) / f32(S_R);
    let delta_j = params.delta_scale * falloff * falloff;
    let inv_range = 1.0 / (delta_j - params.delta0);
    let count = (S_H + j) / (j + 1u);
    var occlusion = 0.0;
    for (var i = 0u; i < count; i++) {
        let reflected = reflect(r1, samples[j * S_H + i].xyz);
        let n_reflected = dot(reflected, n);
        let omega = select(reflected, -reflected, n_reflected < 0.0);
        let offset = vec2<f32>(omega.x, -omega.y) * radius;
        let sample = textureLoad(nd, level_texel(pixel, offset, scale, size), 0);
        if (TAP_FLOOR) {
            occlusion += sample.w;
            continue;
        }
        let dd = centre.w - sample.w;
        // g_depth (Eq. 11-13) without branches: t = 0 below δ0 (weight 1), t = 1 above δ(j)
        // (weight 0), the Hermite h(t) = 3t² - 2t³ between.
        let t = saturate((dd - params.delta0) * inv_range);
        let depth_weight = 1.0 - t * t * (3.0 - 2.0 * t);
        let weight = depth_weight * light_weight(n, omega, abs(n_reflected));
        occlusion += select(0.0, weight, dd > params.epsilon);
    }
    return occlusion / f32(count);
}

// AO_j at `pixel` from level j's (AO_j, d_j): bilinear over the four nearest texels, each
// weight scaled by max(0, 1 - |d_j(t) - d_j(t_P)| / τ), t_P the texel `outer = full` would
// read the centre from (so it always contributes).
fn upsample_outer(outer: texture_2d<f32>, j: u32, pixel: vec2<u32>) -> f32 {
    let scale = params.levels.scale[j].xy;
    let size = vec2<i32>(params.levels.size[j].xy);
    let reference = textureLoad(outer, level_texel(pixel, vec2<f32>(0.0), scale, params.levels.size[j].xy), 0);
    let u = (vec2<f32>(pixel) + 0.5) * scale - 0.5;
    let base = floor(u);
    let f = u - base;
    var sum = 0.0;
    var total = 0.0;
    for (var dy = 0; dy < 2; dy++) {
        for (var dx = 0; dx < 2; dx++) {
            let at = clamp(vec2<i32>(base) + vec2<i32>(dx, dy), vec2<i32>(0), size - 1);
            let texel = textureLoad(outer, at, 0);
            let bilinear = select(1.0 - f.x, f.x, dx == 1) * select(1.0 - f.y, f.y, dy == 1);
            let weight = bilinear * max(1.0 - abs(texel.y - reference.y) / OUTER_DEPTH_TOLERANCE, 0.0);
            sum += weight * texel.x;
            total += weight;
        }
    }
    return select(reference.x, sum / total, total > 0.0);
}

// Σ over lights of the light an occluder with normal `n_o` reflects toward ω: the authors'
// diffuse plus specular with exponent 100 (unweighted by kd, ks).
fn occluder_light(n_o: vec3<f32>, omega: vec3<f32>) -> f32 {
    var reflected = 0.0;
    for (var s = 0u; s < light_count(lighting); s++) {
        let light = lighting.lights[s];
        let half_sum = light.xyz + omega;
        let half_len = length(half_sum);
        let n_h = select(0.0, dot(n_o, half_sum) / half_len, half_len > 1e-12);
        reflected += light.w * (max(dot(n_o, light.xyz), 0.0) + whole_pow(n_h, 100u));
    }
    return reflected;
}

// Variant `reference` at a geometry pixel: every hemisphere on level 0 with s_h samples.
fn reference_ao(pixel: vec2<u32>, r1: vec3<f32>, zoom: f32) -> f32 {
    let size = vec2<f32>(params.levels.size[0].xy);
    let centre = textureLoad(nd0, pixel, 0);
    let n = centre.xyz;
    let base = params.reference_scale * (zoom / max(1.0 - centre.w, 1e-6));
    var total = 0.0;
    var scaler = 0.0;
    for (var l = 0u; l < S_R; l++) {
        scaler += 1.5 + f32(l);
        let falloff = select(1.0, 1.0 - f32(l) / f32(max(S_R, 2u) - 1u), S_R > 1u);
        let density = falloff * falloff;
        var occlusion = 0.0;
        var used = 0u;
        for (var i = 0u; i < S_H; i++) {
            let omega = reflect(samples[l * S_H + i].xyz, r1);
            let n_omega = dot(omega, n);
            let ray = sign(n_omega) * omega;
            let at = vec2<f32>(pixel) + 0.5 + vec2<f32>(ray.x, -ray.y) * (scaler * base);
            if (any(at < vec2<f32>(0.0)) || any(at > size)) {
                continue;
            }
            used += 1u;
            let sample = textureLoad(nd0, min(vec2<i32>(floor(at)), vec2<i32>(size) - 1), 0);
            if (TAP_FLOOR) {
                occlusion += sample.w;
                continue;
            }
            let dd = centre.w - sample.w;
            let t = saturate((dd - REFERENCE_FALLOFF) / (density - REFERENCE_FALLOFF));
            var weight = 1.0 - t * t * (3.0 - 2.0 * t);
            if (LIGHT_ATTENUATION) {
                weight *= 1.5 - max(n_omega, 0.0) * occluder_light(sample.xyz, omega);
            } else {
                weight *= 1.5;
            }
            occlusion += select(0.0, weight, dd >= REFERENCE_FALLOFF);
        }
        total += select(0.0, occlusion / f32(used), used > 0u);
    }
    return max(total / f32(S_R), 0.0);
}

// R1 at `pixel`: the tile indexed relative to the visible viewport's corner.
fn r1_at(pixel: vec2<u32>) -> vec3<f32> {
    let tile = ((vec2<i32>(pixel) - params.noise_origin) % 64 + 64) % 64;
    return noise[tile.y * 64 + tile.x].xyz;
}

@compute @workgroup_size(8, 8, 1)
fn line_ao(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = id.xy;
    if (any(pixel >= textureDimensions(nd0))) {
        return;
    }
    if (nd_is_background(textureLoad(nd0, pixel, 0))) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    let zoom = textureLoad(zoom_map, pixel, 0).r;
    let r1 = r1_at(pixel);
    if (REFERENCE) {
        textureStore(ao_out, pixel, vec4<f32>(reference_ao(pixel, r1, zoom)));
        return;
    }

    var ao = hemisphere(nd0, 0u, pixel, r1, zoom);
    if (OUTER_LEVEL) {
        if (S_R > 1u) {
            ao += upsample_outer(outer1, 1u, pixel);
        }
        if (S_R > 2u) {
            ao += upsample_outer(outer2, 2u, pixel);
        }
        if (S_R > 3u) {
            ao += upsample_outer(outer3, 3u, pixel);
        }
        if (S_R > 4u) {
            ao += upsample_outer(outer4, 4u, pixel);
        }
        textureStore(ao_out, pixel, vec4<f32>(clamp(ao, 0.0, 1.0)));
        return;
    }
    if (S_R > 1u) {
        ao += hemisphere(nd1, 1u, pixel, r1, zoom);
    }
    if (S_R > 2u) {
        ao += hemisphere(nd2, 2u, pixel, r1, zoom);
    }
    if (S_R > 3u) {
        ao += hemisphere(nd3, 3u, pixel, r1, zoom);
    }
    if (S_R > 4u) {
        ao += hemisphere(nd4, 4u, pixel, r1, zoom);
    }
    textureStore(ao_out, pixel, vec4<f32>(clamp(ao, 0.0, 1.0)));
}

// ⌊(t + ½) · size_0 / size_j⌋ in integers: the full-resolution pixel that stands for texel t.
fn representative_pixel(t: vec2<u32>, size_j: vec2<u32>, size_0: vec2<u32>) -> vec2<u32> {
    return min((2u * t + 1u) * size_0 / (2u * size_j), size_0 - 1u);
}

// `outer = level`: hemisphere LEVEL at every texel of its level, evaluated as `line_ao` would
// at the texel's representative pixel; writes (AO_j, d_j).
@compute @workgroup_size(8, 8, 1)
fn line_ao_outer(@builtin(global_invocation_id) id: vec3<u32>) {
    let texel = id.xy;
    let size = params.levels.size[LEVEL].xy;
    if (any(texel >= size)) {
        return;
    }
    var centre: vec4<f32>;
    switch LEVEL {
        case 1u: { centre = textureLoad(nd1, texel, 0); }
        case 2u: { centre = textureLoad(nd2, texel, 0); }
        case 3u: { centre = textureLoad(nd3, texel, 0); }
        default: { centre = textureLoad(nd4, texel, 0); }
    }
    if (nd_is_background(centre)) {
        textureStore(outer_out, texel, vec4<f32>(0.0, centre.w, 0.0, 0.0));
        return;
    }
    let pixel = representative_pixel(texel, size, params.levels.size[0].xy);
    let zoom = textureLoad(zoom_map, pixel, 0).r;
    let r1 = r1_at(pixel);
    var ao: f32;
    switch LEVEL {
        case 1u: { ao = hemisphere(nd1, 1u, pixel, r1, zoom); }
        case 2u: { ao = hemisphere(nd2, 2u, pixel, r1, zoom); }
        case 3u: { ao = hemisphere(nd3, 3u, pixel, r1, zoom); }
        default: { ao = hemisphere(nd4, 4u, pixel, r1, zoom); }
    }
    textureStore(outer_out, texel, vec4<f32>(ao, centre.w, 0.0, 0.0));
}
