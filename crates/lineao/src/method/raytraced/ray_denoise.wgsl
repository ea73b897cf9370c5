// The ray tracer's edge-aware denoiser (`lineao::method::raytraced::denoise`): each geometry pixel's
// running mean sum/rays (every pixel of a picture has traced `rays`) averaged with its neighbours' in a (2r + 1)² window that see the same
// surface — the same stretch of the same line (own segments at most `reach` vertices apart),
// or for surfaces and tubes a depth within `depth_tolerance` of the pixel's — weighted by
// exp(−|Δ|² · spatial) · max(n·n', 0)^normal_power. `spatial` = 1/(2σ²), σ shrinking as
// 1/√rays (0: the window is the pixel, the mean is copied).
#import shared/nd.wgsl
#import shared/view.wgsl

// Keep in sync with `lineao::method::raytraced::denoise::DenoiseUniform`.
struct Denoise {
    view: ViewParams,
    radius: i32,
    spatial: f32,
    normal_power: f32,
    depth_tolerance: f32,
    reach: u32,
    width: u32,
    height: u32,
    rays: u32,
}

@group(0) @binding(0) var<uniform> params: Denoise;
@group(0) @binding(1) var nd0: texture_2d<f32>;
@group(0) @binding(2) var ao_out: texture_storage_2d<r32float, write>;
// The ray tracer's (sum, sum of squares, own segment, buried) per pixel, as bits.
@group(0) @binding(3) var<storage, read> accumulation: array<vec4<u32>>;

const NONE: u32 = 0xffffffffu;

@compute @workgroup_size(8, 8)
fn ray_denoise(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(i32(params.width), i32(params.height));
    let pixel = vec2<i32>(id.xy);
    if pixel.x >= size.x || pixel.y >= size.y {
        return;
    }
    let here = textureLoad(nd0, pixel, 0);
    let centre = accumulation[u32(pixel.y) * params.width + u32(pixel.x)];
    if nd_is_background(here) || params.rays == 0u {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    let n = normalize(here.xyz);
    let z = linear_depth(params.view, here.w);
    let own = centre.z;
    var radius = params.radius;
    if params.spatial == 0.0 {
        radius = 0;
    }
    var sum = 0.0;
    var weight = 0.0;
    for (var dy = -radius; dy <= radius; dy++) {
        for (var dx = -radius; dx <= radius; dx++) {
            let q = pixel + vec2<i32>(dx, dy);
            if any(q < vec2<i32>(0)) || any(q >= size) {
                continue;
            }
            let nd = textureLoad(nd0, q, 0);
            let s = accumulation[u32(q.y) * params.width + u32(q.x)];
            if nd_is_background(nd) {
                continue;
            }
            var same: bool;
            if own != NONE {
                same = s.z != NONE && max(s.z, own) - min(s.z, own) <= params.reach;
            } else {
                same = s.z == NONE && abs(linear_depth(params.view, nd.w) - z) <= params.depth_tolerance * z;
            }
            if !same {
                continue;
            }
            let facing = max(dot(n, normalize(nd.xyz)), 0.0);
            let w = exp(-f32(dx * dx + dy * dy) * params.spatial) * pow(facing, params.normal_power);
            sum += w * (bitcast<f32>(s.x) / f32(params.rays));
            weight += w;
        }
    }
    // The centre always counts (its own surface, facing 1), so weight > 0.
    textureStore(ao_out, pixel, vec4<f32>(sum / weight, 0.0, 0.0, 0.0));
}
