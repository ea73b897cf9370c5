// Separable bilateral blur (a depth-aware Gaussian, as the VO paper uses after its samples):
// one axis per pipeline (AXIS 0 = x, 1 = y), applied x then y. Each geometry neighbour k
// pixels away weighs exp(−k²/(2σ_s²) − Δz²/(2σ_z²)), Δz its linear depth minus the centre's in
// world units; the background neither receives nor gives occlusion.
#import shared/nd.wgsl
#import shared/view.wgsl

override AXIS: u32 = 0u;

// Keep in sync with `lineao::passes::bilateral::BilateralUniform`.
struct BilateralUniform {
    view: ViewParams,
    radius: i32,
    // 1/(2σ_s²) and 1/(2σ_z²).
    spatial: f32,
    depth: f32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: BilateralUniform;
@group(0) @binding(1) var nd0: texture_2d<f32>;
@group(0) @binding(2) var ao_in: texture_2d<f32>;
@group(0) @binding(3) var ao_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn bilateral(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(nd0));
    let pixel = vec2<i32>(id.xy);
    if pixel.x >= size.x || pixel.y >= size.y {
        return;
    }
    let here = textureLoad(nd0, pixel, 0);
    if nd_is_background(here) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    let z = linear_depth(params.view, here.w);
    let step = select(vec2<i32>(0, 1), vec2<i32>(1, 0), AXIS == 0u);
    var sum = 0.0;
    var weight = 0.0;
    for (var k = -params.radius; k <= params.radius; k++) {
        let s = pixel + k * step;
        if any(s < vec2<i32>(0)) || any(s >= size) {
            continue;
        }
        let nd = textureLoad(nd0, s, 0);
        if nd_is_background(nd) {
            continue;
        }
        let dz = linear_depth(params.view, nd.w) - z;
        let w = exp(-f32(k * k) * params.spatial - dz * dz * params.depth);
        sum += w * textureLoad(ao_in, s, 0).x;
        weight += w;
    }
    textureStore(ao_out, pixel, vec4<f32>(sum / weight, 0.0, 0.0, 0.0));
}
