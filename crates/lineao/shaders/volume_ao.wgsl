// Object-space AO per pixel (seed 000 Eq. 4–5): ao = 1 − Σ_o w_o V_o G_o(N) / Σ_o G_o(N), with the
// interpolated octant visibilities V_o of the `octants` target and G_o read bilinearly from an
// octahedral table of the world-space normal. See `lineao::passes::volume_ao`; the arithmetic is
// `lineao::reference::volume_ao`'s (and `GeometryTable::lookup`'s) step by step.
#import shared/nd.wgsl

// Keep in sync with `lineao::passes::volume_ao::VolumeAoUniform`.
struct VolumeAoUniform {
    view_to_world: mat3x3<f32>,
    weights: array<vec4<f32>, 2>,
    table_size: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: VolumeAoUniform;
@group(0) @binding(1) var nd0: texture_2d<f32>;
@group(0) @binding(2) var octants: texture_2d<u32>;
// Per texel (i, j) of the table, row-major: G of octants 0–3, then 4–7.
@group(0) @binding(3) var<storage, read> table: array<vec4<f32>>;
@group(0) @binding(4) var ao_out: texture_storage_2d<r32float, write>;

fn sign_not_zero(p: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
}

// The unit vector `n` on the octahedron, unfolded into [−1, 1]².
fn octahedral_encode(n: vec3<f32>) -> vec2<f32> {
    let m = n / (abs(n.x) + abs(n.y) + abs(n.z));
    let p = m.xy;
    return select((vec2<f32>(1.0) - abs(p.yx)) * sign_not_zero(p), p, m.z >= 0.0);
}

fn table_texel(i: u32, j: u32, half: u32) -> vec4<f32> {
    return table[(i + params.table_size * j) * 2u + half];
}

// G of octants 0–3 (`half` 0) or 4–7 (1) at the unit normal `n`: bilinear, clamped to the map.
fn geometry_term(n: vec3<f32>, half: u32) -> vec4<f32> {
    let size = f32(params.table_size);
    let top = size - 1.0;
    let f = clamp((octahedral_encode(n) + 1.0) * 0.5 * size - 0.5, vec2<f32>(0.0), vec2<f32>(top));
    let base = min(floor(f), vec2<f32>(max(top - 1.0, 0.0)));
    let w = f - base;
    let i = u32(base.x);
    let j = u32(base.y);
    let i1 = min(i + 1u, params.table_size - 1u);
    let j1 = min(j + 1u, params.table_size - 1u);
    let upper = table_texel(i, j, half) * (1.0 - w.x) + table_texel(i1, j, half) * w.x;
    let lower = table_texel(i, j1, half) * (1.0 - w.x) + table_texel(i1, j1, half) * w.x;
    return upper * (1.0 - w.y) + lower * w.y;
}

@compute @workgroup_size(8, 8)
fn volume_ao(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(nd0);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let nd = textureLoad(nd0, pixel, 0);
    if nd_is_background(nd) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    let n = normalize(params.view_to_world * nd.xyz);
    let packed = textureLoad(octants, pixel, 0).xy;
    var lit = 0.0;
    var total = 0.0;
    for (var half = 0u; half < 2u; half++) {
        let v = unpack4x8unorm(packed[half]);
        let g = geometry_term(n, half);
        let w = params.weights[half];
        for (var k = 0u; k < 4u; k++) {
            lit += w[k] * v[k] * g[k];
            total += g[k];
        }
    }
    let visibility = select(0.0, lit / total, total > 0.0);
    textureStore(ao_out, pixel, vec4<f32>(1.0 - visibility, 0.0, 0.0, 0.0));
}
