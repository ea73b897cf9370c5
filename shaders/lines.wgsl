// Line renderer: polylines at a fixed pixel width as triangle strips, writing the G-buffer of
// CONTRACT.md (color, ND map, zoom map, specular, hardware depth).
//
// Every point comes twice (left, right; the sign of tangent.w); the vertex shader pushes it half
// a line width sideways, perpendicular to the screen direction of its *vertex* tangent, so
// consecutive segments share their join corners exactly: joins without gaps or overlaps.
// `lineao::passes::lines` builds the strip.
#import shared/lighting.wgsl

// Keep in sync with `lineao::passes::lines::LineUniform`.
struct LineUniform {
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    constant_color: vec4<f32>,
    // Guard-banded viewport size in pixels.
    viewport: vec2<f32>,
    near: f32,
    far: f32,
    f_px: f32,
    zoom_unit: f32,
    line_width_px: f32,
    orthographic: u32,
    // 0: tangent direction |T| (world axes as RGB), 1: constant color.
    color_mode: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> frame: LineUniform;
@group(0) @binding(1) var<uniform> lighting: Lighting;

struct StripVertex {
    @location(0) p: vec3<f32>,
    // xyz: unit world-space tangent; w: side, > 0 left, < 0 right.
    @location(1) t: vec4<f32>,
}

// Per-vertex octant visibilities (object-space AO) from the attribute stream. Keep in sync with
// `lineao::passes::lines::LineAttributes`.
struct Attributes {
    @location(2) octants_lo: vec4<f32>,
    @location(3) octants_hi: vec4<f32>,
}

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) view_tangent: vec3<f32>,
    @location(2) color: vec3<f32>,
}

// The strip's outputs and the octant visibilities, interpolated along and across the line.
struct VsOutOctants {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) view_tangent: vec3<f32>,
    @location(2) color: vec3<f32>,
    @location(3) octants_lo: vec4<f32>,
    @location(4) octants_hi: vec4<f32>,
}

// Pixel-space direction of the projected curve at clip position `clip`, given the clip-space
// derivative `dclip` along it (quotient rule of x/w, y/w; the positive 1/w^2 is dropped).
fn screen_direction(clip: vec4<f32>, dclip: vec4<f32>) -> vec2<f32> {
    return (dclip.xy * clip.w - clip.xy * dclip.w) * frame.viewport;
}

// Point `p` with tangent `t_world`, pushed `side` half line widths to its left (−1 right, 0 on it).
fn line_vertex(p: vec3<f32>, t_world: vec3<f32>, side: f32) -> VsOut {
    var out: VsOut;
    let view_pos = frame.view * vec4<f32>(p, 1.0);
    let view_tangent = (frame.view * vec4<f32>(t_world, 0.0)).xyz;
    let clip = frame.proj * view_pos;

    let dir = screen_direction(clip, frame.proj * vec4<f32>(view_tangent, 0.0));
    // A tangent along the view ray has no screen direction: any sideways offset will do.
    let sideways = select(vec2<f32>(0.0, 1.0), normalize(vec2<f32>(-dir.y, dir.x)), dot(dir, dir) >= 1e-12);
    // Half the width in pixels is w/2 * 2/viewport in NDC.
    let offset_ndc = sideways * side * frame.line_width_px / frame.viewport;

    out.clip = vec4<f32>(clip.xy + offset_ndc * clip.w, clip.zw);
    out.view_pos = view_pos.xyz;
    out.view_tangent = view_tangent;
    if (frame.color_mode == 0u) {
        out.color = abs(t_world) / max(length(t_world), 1e-20);
    } else {
        out.color = frame.constant_color.rgb;
    }
    return out;
}

// Fixed-width lines: the triangle strip.
@vertex
fn vs_main(v: StripVertex) -> VsOut {
    return line_vertex(v.p, v.t.xyz, sign(v.t.w));
}

// Native 1-px lines (an indexed `LineList` over the same vertices): the rasterizer's own thin
// lines, the baseline the strip is measured against (`lineao bench`, pass `lines-native-1px`).
@vertex
fn vs_native(v: StripVertex) -> VsOut {
    return line_vertex(v.p, v.t.xyz, 0.0);
}

// Fixed-width lines with the octant visibilities of the attribute stream.
@vertex
fn vs_octants(v: StripVertex, a: Attributes) -> VsOutOctants {
    return with_octants(line_vertex(v.p, v.t.xyz, sign(v.t.w)), a.octants_lo, a.octants_hi);
}

// Fixed-width lines of geometry without attributes, into a G-buffer with octants: all visible.
@vertex
fn vs_visible(v: StripVertex) -> VsOutOctants {
    return with_octants(line_vertex(v.p, v.t.xyz, sign(v.t.w)), vec4<f32>(1.0), vec4<f32>(1.0));
}

fn with_octants(base: VsOut, lo: vec4<f32>, hi: vec4<f32>) -> VsOutOctants {
    return VsOutOctants(base.clip, base.view_pos, base.view_tangent, base.color, lo, hi);
}

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

@fragment
fn fs_main(in: VsOut) -> GBuffer {
    return gbuffer(in.view_pos, in.view_tangent, in.color);
}

@fragment
fn fs_octants(in: VsOutOctants) -> GBufferOctants {
    let g = gbuffer(in.view_pos, in.view_tangent, in.color);
    let octants = vec2<u32>(pack4x8unorm(in.octants_lo), pack4x8unorm(in.octants_hi));
    return GBufferOctants(g.color, g.nd, g.zoom, g.specular, octants);
}

// The G-buffer of a point of the line at `view_pos` with tangent `view_tangent`.
fn gbuffer(view_pos: vec3<f32>, view_tangent: vec3<f32>, color: vec3<f32>) -> GBuffer {
    let t = normalize(view_tangent);
    // C: from the point toward the eye (orthographic: the eye is at infinity along +z).
    let c = select(normalize(-view_pos), vec3<f32>(0.0, 0.0, 1.0), frame.orthographic != 0u);
    // n = (T x C) x T (paper §3.2): perpendicular to T, in the plane of T and C, facing the eye.
    var n = cross(cross(t, c), t);
    n = select(c, normalize(n), dot(n, n) > 1e-12);
    n = select(n, -n, dot(n, c) < 0.0);

    let depth = -view_pos.z;
    let d = clamp((depth - frame.near) / (frame.far - frame.near), 0.0, 1.0);
    let zoom = select(frame.f_px * frame.zoom_unit / depth, frame.f_px * frame.zoom_unit, frame.orthographic != 0u);

    // Illuminated lines (Zöckler et al. 1996, Mallo et al. 2005): the specular maximum over the
    // circle of normals of an infinitesimal cylinder, added on top of LineAO (paper §3.3).
    var specular = 0.0;
    let v_t = dot(c, t);
    for (var s = 0u; s < lighting.count; s++) {
        let light = lighting.lights[s];
        let l_t = dot(light.xyz, t);
        let cos_rv = sqrt(max(1.0 - l_t * l_t, 0.0)) * sqrt(max(1.0 - v_t * v_t, 0.0)) - l_t * v_t;
        specular += light.w * lighting.ks * clamped_pow(cos_rv, lighting.shininess);
    }

    var out: GBuffer;
    out.color = vec4<f32>(color, 1.0);
    out.nd = vec4<f32>(n, d);
    out.zoom = zoom;
    out.specular = specular;
    return out;
}
