// Object-space AO of one point (seed 000 Eq. 4–5): ao = 1 − Σ_o w_o V_o G_o(N) / Σ_o G_o(N), with
// the octant visibilities V_o and G_o read bilinearly from an octahedral table of the world-space
// normal N (`lineao::passes::volume_ao`; the arithmetic is `lineao::reference::volume_ao`'s and
// `GeometryTable::lookup`'s step by step). A file that imports this one declares the uniform
// `volume_params: VolumeAoUniform` and the table `volume_table: array<vec4<f32>>` (per texel
// (i, j), row-major: G of octants 0–3, then 4–7) in its own bind groups.

// Keep in sync with `lineao::passes::volume_ao::VolumeAoUniform`.
struct VolumeAoUniform {
    view_to_world: mat3x3<f32>,
    weights: array<vec4<f32>, 2>,
    table_size: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

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
    return volume_table[(i + volume_params.table_size * j) * 2u + half];
}

// G of octants 0–3 (`half` 0) or 4–7 (1) at the unit normal `n`: bilinear, clamped to the map.
fn geometry_term(n: vec3<f32>, half: u32) -> vec4<f32> {
    let size = f32(volume_params.table_size);
    let top = size - 1.0;
    let f = clamp((octahedral_encode(n) + 1.0) * 0.5 * size - 0.5, vec2<f32>(0.0), vec2<f32>(top));
    let base = min(floor(f), vec2<f32>(max(top - 1.0, 0.0)));
    let w = f - base;
    let i = u32(base.x);
    let j = u32(base.y);
    let i1 = min(i + 1u, volume_params.table_size - 1u);
    let j1 = min(j + 1u, volume_params.table_size - 1u);
    let upper = table_texel(i, j, half) * (1.0 - w.x) + table_texel(i1, j, half) * w.x;
    let lower = table_texel(i, j1, half) * (1.0 - w.x) + table_texel(i1, j1, half) * w.x;
    return upper * (1.0 - w.y) + lower * w.y;
}

// The occlusion at a point of view-space normal `view_normal` whose octant visibilities are
// `packed` (`pack4x8unorm` of octants 0–3 and 4–7, as the `octants` target holds them).
fn object_ao(view_normal: vec3<f32>, packed: vec2<u32>) -> f32 {
    let n = normalize(volume_params.view_to_world * view_normal);
    var lit = 0.0;
    var total = 0.0;
    for (var half = 0u; half < 2u; half++) {
        let v = unpack4x8unorm(packed[half]);
        let g = geometry_term(n, half);
        let w = volume_params.weights[half];
        for (var k = 0u; k < 4u; k++) {
            lit += w[k] * v[k] * g[k];
            total += g[k];
        }
    }
    let visibility = select(0.0, lit / total, total > 0.0);
    return 1.0 - visibility;
}
