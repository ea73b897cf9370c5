// Crytek SSAO (Mittring 2007, "Finding next gen: CryEngine 2"), the LineAO paper's baseline:
// N point samples in a sphere of radius R around the view-space position P, the kernel
// reflected about a vector from a 4 x 4 tile (the matching 4 x 4 blur removes the pattern).
// A sample q is occluded when the visible surface at q's pixel is in front of q by more than
// ε and less than the range:
//
//   ao(P) = 1/N sum_i [ε < depth(q_i) − surface(pixel(q_i)) < range],  q_i = P + R reflect(k_i, r(P))
//
// A flat surface facing the camera is half occluded (the samples behind it): Crytek's look.
#import shared/nd.wgsl
#import shared/view.wgsl

override SAMPLES: u32 = 16u;
// SSAO_EPSILON: Rust's `lineao::method::ssao::SSAO_EPSILON`.
#import rust/constants.wgsl

// Keep in sync with `lineao::method::ssao::SsaoUniform`.
struct SsaoUniform {
    view: ViewParams,
    noise_origin: vec2<i32>,
    radius: f32,
    range: f32,
}

@group(0) @binding(0) var<uniform> params: SsaoUniform;
// kernel[0..SAMPLES]: points in the unit sphere; noise[16..32]: the 4 x 4 rotation tile.
@group(0) @binding(1) var<uniform> tables: array<vec4<f32>, 48>;
@group(0) @binding(2) var nd0: texture_2d<f32>;
@group(0) @binding(3) var ao_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn ssao(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(nd0);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = id.xy;
    let here = textureLoad(nd0, pixel, 0);
    if nd_is_background(here) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    let v = params.view;
    let depth = linear_depth(v, here.w);
    let pos = view_position(v, pixel, depth);
    let tile = ((vec2<i32>(pixel) - params.noise_origin) % 4 + 4) % 4;
    let r = tables[32 + tile.y * 4 + tile.x].xyz;
    let epsilon = SSAO_EPSILON * (v.far - v.near);
    let last = vec2<f32>(size) - 1.0;
    var occluded = 0u;
    for (var i = 0u; i < SAMPLES; i++) {
        let k0 = tables[i].xyz;
        let dot_rk = r.x * k0.x + r.y * k0.y + r.z * k0.z;
        let k = k0 - 2.0 * dot_rk * r;
        let q = pos + params.radius * k;
        let q_depth = -q.z;
        if q_depth <= 0.0 {
            continue;
        }
        let t = vec2<i32>(clamp(floor(project(v, q)), vec2<f32>(0.0), last));
        let surface = linear_depth(v, textureLoad(nd0, t, 0).w);
        let diff = q_depth - surface;
        if diff > epsilon && diff < params.range {
            occluded += 1u;
        }
    }
    textureStore(ao_out, pixel, vec4<f32>(f32(occluded) / f32(SAMPLES), 0.0, 0.0, 0.0));
}
