// Line renderer: polylines at a fixed pixel width, expanded to screen-aligned quads in the vertex
// shader, writing the G-buffer of CONTRACT.md (color, ND map, zoom map, specular, hardware depth).
//
// Each instance is one segment (p0, p1). The same point buffer is bound twice, the second time one
// point further on, so instance k reads points k and k + 1 without duplicating data. A point's
// tangent.w says whether a segment starts there (0 at a streamline's last point: the instance
// becomes a degenerate, culled quad). Each quad corner is pushed sideways perpendicular to the
// *vertex* tangent's screen direction, so consecutive segments share their join corners exactly:
// joins without gaps or overlaps.
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

struct SegmentIn {
    @location(0) p0: vec3<f32>,
    @location(1) t0: vec4<f32>,
    @location(2) p1: vec3<f32>,
    @location(3) t1: vec4<f32>,
}

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) view_tangent: vec3<f32>,
    @location(2) color: vec3<f32>,
}

// Pixel-space direction of the projected curve at clip position `clip`, given the clip-space
// derivative `dclip` along it (quotient rule of x/w, y/w; the positive 1/w^2 is dropped).
fn screen_direction(clip: vec4<f32>, dclip: vec4<f32>) -> vec2<f32> {
    return (dclip.xy * clip.w - clip.xy * dclip.w) * frame.viewport;
}

// Vertex `at_end` of the segment, pushed `side` half line widths to its left (−1 right, 0 on it).
fn segment_vertex(seg: SegmentIn, at_end: bool, side: f32) -> VsOut {
    var out: VsOut;
    if (seg.t0.w < 0.5) {
        // No segment starts at p0: a degenerate primitive outside the clip volume.
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    let p = select(seg.p0, seg.p1, at_end);
    let t_world = select(seg.t0.xyz, seg.t1.xyz, at_end);

    let view_pos = frame.view * vec4<f32>(p, 1.0);
    let view_tangent = (frame.view * vec4<f32>(t_world, 0.0)).xyz;
    let clip = frame.proj * view_pos;

    var dir = screen_direction(clip, frame.proj * vec4<f32>(view_tangent, 0.0));
    if (dot(dir, dir) < 1e-12) {
        // Tangent along the view ray: fall back to the segment's own screen direction.
        let c0 = frame.proj * frame.view * vec4<f32>(seg.p0, 1.0);
        let c1 = frame.proj * frame.view * vec4<f32>(seg.p1, 1.0);
        dir = (c1.xy / c1.w - c0.xy / c0.w) * frame.viewport;
    }
    dir = select(vec2<f32>(1.0, 0.0), normalize(dir), dot(dir, dir) >= 1e-12);
    // Half the width in pixels is w/2 * 2/viewport in NDC.
    let offset_ndc = vec2<f32>(-dir.y, dir.x) * side * frame.line_width_px / frame.viewport;

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

// Quads: vertices 0..4 of a triangle strip, (start, right), (start, left), (end, right), (end, left).
@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32, seg: SegmentIn) -> VsOut {
    return segment_vertex(seg, (vertex_index >> 1u) == 1u, f32(vertex_index & 1u) * 2.0 - 1.0);
}

// Native 1-px lines (`LineList`, vertices 0..2): the rasterizer's own thin lines, the baseline the
// quads are measured against (`lineao bench`, pass `lines-native-1px`).
@vertex
fn vs_native(@builtin(vertex_index) vertex_index: u32, seg: SegmentIn) -> VsOut {
    return segment_vertex(seg, vertex_index == 1u, 0.0);
}

struct GBuffer {
    @location(0) color: vec4<f32>,
    @location(1) nd: vec4<f32>,
    @location(2) zoom: f32,
    @location(3) specular: f32,
}

@fragment
fn fs_main(in: VsOut) -> GBuffer {
    let t = normalize(in.view_tangent);
    // C: from the point toward the eye (orthographic: the eye is at infinity along +z).
    let c = select(normalize(-in.view_pos), vec3<f32>(0.0, 0.0, 1.0), frame.orthographic != 0u);
    // n = (T x C) x T (paper §3.2): perpendicular to T, in the plane of T and C, facing the eye.
    var n = cross(cross(t, c), t);
    n = select(c, normalize(n), dot(n, n) > 1e-12);
    n = select(n, -n, dot(n, c) < 0.0);

    let depth = -in.view_pos.z;
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
    out.color = vec4<f32>(in.color, 1.0);
    out.nd = vec4<f32>(n, d);
    out.zoom = zoom;
    out.specular = specular;
    return out;
}
