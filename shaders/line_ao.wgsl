// LineAO (Eichelbaum et al., TVCG 2013, Eq. 7): ambient occlusion of dense lines summed over
// s_r hemispheres of growing radius, each read from its own level of the Gaussian ND pyramid.
//
//   LineAO(P) = clamp( sum_j AO_j(P), 0, 1 )                                       (Eq. 7)
//   AO_j(P)   = 1/n_j sum_i [Δd > ε] · g_depth(Δd, j) · g_light(n_j(P), ω_i)      (Eq. 6, 9)
//   Δd        = d_j(P) - d_j(P + r_j (ω.x, -ω.y))                                  (Eq. 10)
//   n_j = ceil(s_h / (j + 1)),  r_j = r0 + j · z(P) pixels
//   ω_i = reflect(R1(P), R2[j][i]), flipped into n_j(P)'s hemisphere
//
// The occlusion test departs from Eq. 8 on purpose (Δd > ε, not Δd >= 0): see CONTRACT.md.
#import shared/nd.wgsl
#import shared/lighting.wgsl

// Compile-time sample counts so that the loops can unroll (paper §3.4).
override S_R: u32 = 3u;
override S_H: u32 = 32u;

// Keep in sync with `lineao::passes::line_ao::LineAoUniform`.
struct LineAoUniform {
    levels: Levels,
    // Pixel coordinate of the visible viewport's top-left corner (the guard band's width).
    noise_origin: vec2<i32>,
    r0_px: f32,
    delta0: f32,
    epsilon: f32,
    light_attenuation: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: LineAoUniform;
@group(0) @binding(1) var<uniform> lighting: Lighting;
// R1: 64 x 64 tile of unit vectors, row-major noise[y][x].
@group(0) @binding(2) var<storage, read> noise: array<vec4<f32>>;
// R2: samples[j * S_H + i], unit vectors.
@group(0) @binding(3) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(4) var zoom_map: texture_2d<f32>;
@group(0) @binding(5) var ao_out: texture_storage_2d<r32float, write>;
@group(0) @binding(6) var nd0: texture_2d<f32>;
@group(0) @binding(7) var nd1: texture_2d<f32>;
@group(0) @binding(8) var nd2: texture_2d<f32>;
@group(0) @binding(9) var nd3: texture_2d<f32>;
@group(0) @binding(10) var nd4: texture_2d<f32>;

// Hermite smoothstep h(x) = 3x^2 - 2x^3 (Eq. 13).
fn hermite(x: f32) -> f32 {
    return x * x * (3.0 - 2.0 * x);
}

// Depth-based attenuation (Eq. 11-12; its third case reads Δd where the paper prints d_l).
fn depth_weight(dd: f32, delta_j: f32) -> f32 {
    if (dd > delta_j) {
        return 0.0;
    }
    if (dd < params.delta0) {
        return 1.0;
    }
    return 1.0 - hermite((dd - params.delta0) / (delta_j - params.delta0));
}

// Illumination-based attenuation (Eq. 14-15): 1 - min(sum over lights of the Blinn-Phong BRDF
// lit from L_s and seen from ω, 1).
fn light_weight(n: vec3<f32>, omega: vec3<f32>) -> f32 {
    if (params.light_attenuation == 0u) {
        return 1.0;
    }
    var reflected = 0.0;
    for (var s = 0u; s < lighting.count; s++) {
        let light = lighting.lights[s];
        let half_sum = light.xyz + omega;
        let half_len = length(half_sum);
        let n_h = select(0.0, dot(n, half_sum) / half_len, half_len > 1e-12);
        reflected += light.w * (lighting.kd * max(dot(n, light.xyz), 0.0)
            + lighting.ks * clamped_pow(n_h, lighting.shininess));
    }
    return 1.0 - min(reflected, 1.0);
}

// AO_j(P, r0 + j z(P)) of Eq. 6 on pyramid level `nd`.
fn hemisphere(nd: texture_2d<f32>, j: u32, pixel: vec2<u32>, r1: vec3<f32>, zoom: f32) -> f32 {
    let scale = params.levels.scale[j].xy;
    let size = params.levels.size[j].xy;
    let centre = textureLoad(nd, level_texel(pixel, vec2<f32>(0.0), scale, size), 0);
    let n = centre.xyz;
    let radius = params.r0_px + f32(j) * zoom;
    let falloff = 1.0 - f32(j) / f32(S_R);
    let delta_j = falloff * falloff;
    let count = (S_H + j) / (j + 1u);
    var occlusion = 0.0;
    for (var i = 0u; i < count; i++) {
        var omega = reflect(r1, samples[j * S_H + i].xyz);
        omega = select(omega, -omega, dot(omega, n) < 0.0);
        let offset = vec2<f32>(omega.x, -omega.y) * radius;
        let sample = textureLoad(nd, level_texel(pixel, offset, scale, size), 0);
        let dd = centre.w - sample.w;
        if (dd > params.epsilon) {
            occlusion += depth_weight(dd, delta_j) * light_weight(n, omega);
        }
    }
    return occlusion / f32(count);
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
    let tile = ((vec2<i32>(pixel) - params.noise_origin) % 64 + 64) % 64;
    let r1 = noise[tile.y * 64 + tile.x].xyz;

    var ao = hemisphere(nd0, 0u, pixel, r1, zoom);
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
