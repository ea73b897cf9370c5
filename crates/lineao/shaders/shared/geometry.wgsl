// What lineao's geometry passes (lines, tubes, meshes) read per frame.
#import shared/gbuffer.wgsl
#import shared/lighting.wgsl

// Keep in sync with `lineao::gbuffer::GeometryUniform`.
struct GeometryUniform {
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    inv_proj: mat4x4<f32>,
    constant_color: vec4<f32>,
    // Guard-banded viewport size in pixels.
    viewport: vec2<f32>,
    near: f32,
    far: f32,
    f_px: f32,
    zoom_unit: f32,
    line_width_px: f32,
    orthographic: u32,
    // 0: tangent direction |T| (world axes as RGB), 1: constant color, 2: the vertex's scalar
    // through the colormap, 3: the cull's pieces (`piece_color`; gray where drawn whole).
    color_mode: u32,
    // Tubes: the radius in world units where the geometry carries none.
    tube_radius: f32,
    // 2 / viewport: NDC units per pixel.
    ndc_per_px: vec2<f32>,
    // Color mode 2: xy the scalars at the colormap's ends; its table of linear RGB.
    scalar_range: vec4<f32>,
    // A slab in eye space: the signed distance dot(xyz, p) + w; x of `slab_half` its half
    // thickness, negative without one.
    slab_plane: vec4<f32>,
    slab_half: vec4<f32>,
    colormap: array<vec4<f32>, 16>,
}

@group(0) @binding(0) var<uniform> frame: GeometryUniform;
@group(0) @binding(1) var<uniform> lighting: Lighting;

fn is_orthographic() -> bool {
    return frame.orthographic != 0u;
}

// Whether eye-space point `view_pos` lies outside the slab (never without one): the lines'
// and tubes' fragments there are discarded.
fn outside_slab(view_pos: vec3<f32>) -> bool {
    let half = frame.slab_half.x;
    return half >= 0.0 && abs(dot(frame.slab_plane.xyz, view_pos) + frame.slab_plane.w) > half;
}

// Phong lighting of a surface with unit normal n seen along unit v (toward the eye): the
// (diffuse, specular) sums over the lights, before kd and with ks (meshes, tubes).
fn phong(n: vec3<f32>, v: vec3<f32>) -> vec2<f32> {
    var diffuse = 0.0;
    var specular = 0.0;
    for (var k = 0u; k < light_count(lighting); k++) {
        let light = lighting.lights[k];
        diffuse += light.w * max(dot(n, light.xyz), 0.0);
        specular += light.w * lighting.ks * specular_pow(dot(n, normalize(light.xyz + v)), lighting.shininess);
    }
    return vec2<f32>(diffuse, specular);
}

// The base color of a point with world-space tangent `t_world` and scalar `scalar`: |T| (tangent
// color mode), the constant color, or the scalar through the colormap.
fn base_color(t_world: vec3<f32>, scalar: f32) -> vec3<f32> {
    if frame.color_mode == 0u {
        return abs(t_world) / max(length(t_world), 1e-20);
    }
    if frame.color_mode == 2u {
        // NaN (a sampled volume outside its voxels): 50 % gray.
        if (bitcast<u32>(scalar) & 0x7fffffffu) > 0x7f800000u {
            return vec3<f32>(0.5);
        }
        let span = frame.scalar_range.y - frame.scalar_range.x;
        let t = saturate(select(0.0, (scalar - frame.scalar_range.x) / span, span != 0.0));
        let x = t * 15.0;
        let k = min(u32(x), 14u);
        return mix(frame.colormap[k].rgb, frame.colormap[k + 1u].rgb, x - f32(k));
    }
    if frame.color_mode == 3u {
        return vec3<f32>(0.5);
    }
    return frame.constant_color.rgb;
}

// Color mode 3: a culled piece drawn keeping every `stride`-th point (1 blue, 2 green, 4
// orange, 8 red), or one the cull left out (`left`: 1 outside the view light gray, 2 behind
// what it drew purple).
fn piece_color(stride: u32, left: u32) -> vec3<f32> {
    if left == 1u {
        return vec3<f32>(0.8);
    }
    if left == 2u {
        return vec3<f32>(0.65, 0.2, 0.85);
    }
    let colors = array<vec3<f32>, 4>(
        vec3<f32>(0.15, 0.35, 1.0),
        vec3<f32>(0.1, 0.75, 0.25),
        vec3<f32>(1.0, 0.55, 0.05),
        vec3<f32>(0.9, 0.1, 0.1),
    );
    return colors[min(countTrailingZeros(stride), 3u)];
}

// The G-buffer's targets, in attachment order; octants only where object-space AO is on.
struct GBuffer {
    @location(0) color: vec4<f32>,
    @location(1) nd: vec4<f32>,
    @location(2) zoom: f32,
    @location(3) specular: f32,
}

struct GBufferOctants {
    @location(0) color: vec4<f32>,
    @location(1) nd: vec4<f32>,
    @location(2) zoom: f32,
    @location(3) specular: f32,
    // Octants 0–3 and 4–7 as unorm8 each (`pack4x8unorm`: x in the low byte).
    @location(4) octants: vec2<u32>,
}

fn with_octants(g: GBuffer, lo: vec4<f32>, hi: vec4<f32>) -> GBufferOctants {
    return GBufferOctants(g.color, g.nd, g.zoom, g.specular, vec2<u32>(pack4x8unorm(lo), pack4x8unorm(hi)));
}
