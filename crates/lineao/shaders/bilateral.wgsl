// Separable bilateral blur (a depth-aware Gaussian, as the VO paper uses after its samples):
// one axis per pipeline (AXIS 0 = x, 1 = y), applied x then y. Each geometry neighbour k
// pixels away weighs exp(−k²/(2σ_s²) − Δz²/(2σ_z²)), Δz its linear depth minus the centre's in
// world units; the background neither receives nor gives occlusion. With `slices_only` only the
// anatomy slices' pixels (the G-buffer colour's alpha 0, `shaders/slices.wgsl`) receive: every
// other keeps its occlusion as it is.
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
    // 1: only the slices' pixels are blurred.
    slices_only: u32,
    // The first pixel of the x half (xy) and of the y half (zw): the slices' rectangle.
    origin: vec4<i32>,
}

@group(0) @binding(0) var<uniform> params: BilateralUniform;
@group(0) @binding(1) var nd0: texture_2d<f32>;
@group(0) @binding(2) var ao_in: texture_2d<f32>;
@group(0) @binding(3) var ao_out: texture_storage_2d<r32float, write>;
@group(0) @binding(4) var color: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn bilateral(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(nd0));
    let pixel = vec2<i32>(id.xy) + select(params.origin.zw, params.origin.xy, AXIS == 0u);
    if pixel.x >= size.x || pixel.y >= size.y {
        return;
    }
    let here = textureLoad(nd0, pixel, 0);
    if nd_is_background(here) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    if params.slices_only != 0u && textureLoad(color, pixel, 0).a != 0.0 {
        textureStore(ao_out, pixel, textureLoad(ao_in, pixel, 0));
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
