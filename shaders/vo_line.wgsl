// Volumetric Obscurance with line samples (Loos & Sloan 2010, §4.1, §4.3, §4.4): the fraction
// of a sphere of radius R around P that the depth buffer leaves free, integrated analytically
// along N vertical lines through the sphere at disk points s_i with weights A_i:
//
//   ao(P) = 1 − Σ A_i |free ∩ allowed|_i / Σ A_i |allowed|_i
//   chord [−z_s, z_s], z_s = √(1 − |s|²);  free = z_d ≤ d_r (plus z_d > d_r + thickness)
//   d_r = (depth at P + (s.x, −s.y) R z(P)/zoom_unit − depth(P)) / R
//   allowed: with the normal clamp, n.x s.x + n.y s.y − n.z z_d ≥ 0
//
// Without the clamp a plane facing the camera is exactly half free; with it, wholly free.
// Each pixel reflects its samples about a 2D direction from a 4 x 4 tile.
#import shared/nd.wgsl
#import shared/view.wgsl

override SAMPLES: u32 = 9u;

// Keep in sync with `lineao::passes::vo_line::VoUniform`.
struct VoUniform {
    view: ViewParams,
    noise_origin: vec2<i32>,
    radius: f32,
    zoom_unit: f32,
    // In units of the radius; 0 = off.
    thickness: f32,
    normal_clamp: u32,
    _pad: vec2<u32>,
}

@group(0) @binding(0) var<uniform> params: VoUniform;
// samples[0..16]: (x, y, A_i); tile[16..32]: (u.x, u.y) unit 2D directions.
@group(0) @binding(1) var<uniform> tables: array<vec4<f32>, 32>;
@group(0) @binding(2) var nd0: texture_2d<f32>;
@group(0) @binding(3) var zoom_map: texture_2d<f32>;
@group(0) @binding(4) var ao_out: texture_storage_2d<r32float, write>;

// (free, allowed) of one line sample; `lineao::reference::vo_line_sample`.
fn line_sample(s: vec2<f32>, d_r: f32, n: vec3<f32>) -> vec2<f32> {
    let z_s = sqrt(max(1.0 - (s.x * s.x + s.y * s.y), 0.0));
    var lo = -z_s;
    var hi = z_s;
    if params.normal_clamp != 0u {
        let c = n.x * s.x + n.y * s.y;
        if abs(n.z) < 1e-6 {
            if c < 0.0 {
                hi = lo;
            }
        } else if n.z > 0.0 {
            hi = min(hi, c / n.z);
        } else {
            lo = max(lo, c / n.z);
        }
    }
    let allowed = max(hi - lo, 0.0);
    var free = max(min(hi, d_r) - lo, 0.0);
    if params.thickness > 0.0 {
        free += max(hi - max(lo, d_r + params.thickness), 0.0);
    }
    return vec2<f32>(min(free, allowed), allowed);
}

@compute @workgroup_size(8, 8)
fn vo_line(@builtin(global_invocation_id) id: vec3<u32>) {
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
    let scale = params.radius * textureLoad(zoom_map, pixel, 0).x / params.zoom_unit;
    let tile = ((vec2<i32>(pixel) - params.noise_origin) % 4 + 4) % 4;
    let u = tables[16 + tile.y * 4 + tile.x].xy;
    let last = vec2<f32>(size) - 1.0;
    var free = 0.0;
    var allowed = 0.0;
    for (var i = 0u; i < SAMPLES; i++) {
        let sample = tables[i];
        let dot_su = sample.x * u.x + sample.y * u.y;
        let s = vec2<f32>(2.0 * dot_su * u.x - sample.x, 2.0 * dot_su * u.y - sample.y);
        let at = vec2<f32>(f32(pixel.x) + 0.5 + s.x * scale, f32(pixel.y) + 0.5 - s.y * scale);
        let t = vec2<i32>(clamp(floor(at), vec2<f32>(0.0), last));
        let d_r = (linear_depth(v, textureLoad(nd0, t, 0).w) - depth) / params.radius;
        let fa = line_sample(s, d_r, here.xyz);
        free += sample.z * fa.x;
        allowed += sample.z * fa.y;
    }
    var ao = 0.0;
    if allowed > 0.0 {
        ao = 1.0 - free / allowed;
    }
    textureStore(ao_out, pixel, vec4<f32>(ao, 0.0, 0.0, 0.0));
}
