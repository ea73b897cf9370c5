// Line renderer: polylines at a fixed pixel width as triangle strips, writing the G-buffer of
// CONTRACT.md (color, ND map, zoom map, specular, hardware depth).
//
// Every point comes twice (left, right; the sign of tangent.w); the vertex shader pushes it half
// a line width sideways, perpendicular to the screen direction of its *vertex* tangent, so
// consecutive segments share their join corners exactly: joins without gaps or overlaps.
// `lineao::passes::lines` builds the strip, and the alternating index strip over it that takes
// one side per point where that stays within half a pixel (the same shaders draw both).
#import shared/geometry.wgsl

struct StripVertex {
    @location(0) p: vec3<f32>,
    // xyz: unit world-space tangent; w: side (> 0 left, < 0 right) and flags in its magnitude.
    @location(1) t: vec4<f32>,
}

// The attribute stream: octant visibilities (object-space AO) and the scalar of the colormap
// (the radius at location 4 is the tubes'). Keep in sync with
// `lineao::passes::lines::LineAttributes`.
struct Attributes {
    @location(2) octants_lo: vec4<f32>,
    @location(3) octants_hi: vec4<f32>,
    @location(5) scalar: f32,
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

// Clip position `clip` of a point with view-space tangent `view_tangent`, pushed `offset_px`
// pixels to its left (negative: right), perpendicular to the curve on screen.
fn push_sideways(clip: vec4<f32>, view_tangent: vec3<f32>, offset_px: f32) -> vec4<f32> {
    let dir = screen_direction(clip, frame.proj * vec4<f32>(view_tangent, 0.0));
    let length2 = dot(dir, dir);
    // A tangent along the view ray has no screen direction: any sideways offset will do. One
    // inverse square root and no division: this runs twice per point (`lineao bench`, 11 M
    // vertices: `lines` / `lines-native-1px` 1.34 -> 1.18).
    let sideways = select(vec2<f32>(0.0, 1.0), vec2<f32>(-dir.y, dir.x) * inverseSqrt(length2), length2 >= 1e-12);
    return vec4<f32>(clip.xy + sideways * (offset_px * clip.w) * frame.ndc_per_px, clip.zw);
}

// Point `p` with tangent `t_world` and scalar `scalar`, pushed `side` half line widths to its
// left (−1 right, 0 on it).
fn line_vertex(p: vec3<f32>, t_world: vec3<f32>, side: f32, scalar: f32) -> VsOut {
    var out: VsOut;
    let view_pos = frame.view * vec4<f32>(p, 1.0);
    let view_tangent = (frame.view * vec4<f32>(t_world, 0.0)).xyz;
    out.clip = push_sideways(frame.proj * view_pos, view_tangent, side * 0.5 * frame.line_width_px);
    out.view_pos = view_pos.xyz;
    out.view_tangent = view_tangent;
    out.color = base_color(t_world, scalar);
    return out;
}

// Fixed-width lines: the triangle strip.
@vertex
fn vs_main(v: StripVertex) -> VsOut {
    return line_vertex(v.p, v.t.xyz, sign(v.t.w), 0.0);
}

// Fixed-width lines with the attribute stream (the scalar's color), no octants.
@vertex
fn vs_attributes(v: StripVertex, a: Attributes) -> VsOut {
    return line_vertex(v.p, v.t.xyz, sign(v.t.w), a.scalar);
}

// Native 1-px lines (an indexed `LineList` over the same vertices): the rasterizer's own thin
// lines, the baseline the strip is measured against (`lineao bench`, pass `lines-native-1px`).
@vertex
fn vs_native(v: StripVertex) -> VsOut {
    return line_vertex(v.p, v.t.xyz, 0.0, 0.0);
}

// Fixed-width lines with the octant visibilities of the attribute stream.
@vertex
fn vs_octants(v: StripVertex, a: Attributes) -> VsOutOctants {
    let b = line_vertex(v.p, v.t.xyz, sign(v.t.w), a.scalar);
    return VsOutOctants(b.clip, b.view_pos, b.view_tangent, b.color, a.octants_lo, a.octants_hi);
}

// Fixed-width lines of geometry without attributes, into a G-buffer with octants: all visible.
@vertex
fn vs_visible(v: StripVertex) -> VsOutOctants {
    let b = line_vertex(v.p, v.t.xyz, sign(v.t.w), 0.0);
    return VsOutOctants(b.clip, b.view_pos, b.view_tangent, b.color, vec4<f32>(1.0), vec4<f32>(1.0));
}

@fragment
fn fs_main(in: VsOut) -> GBuffer {
    return line_gbuffer(in.view_pos, in.view_tangent, in.color);
}

@fragment
fn fs_octants(in: VsOutOctants) -> GBufferOctants {
    return with_octants(line_gbuffer(in.view_pos, in.view_tangent, in.color), in.octants_lo, in.octants_hi);
}

// The G-buffer of a point of the line at `view_pos` with tangent `view_tangent`.
fn line_gbuffer(view_pos: vec3<f32>, view_tangent: vec3<f32>, color: vec3<f32>) -> GBuffer {
    let t = normalize(view_tangent);
    let c = gbuffer_eye_direction(view_pos, is_orthographic());
    let n = gbuffer_line_normal(t, c);

    // Illuminated lines (paper §3.3): Zöckler's specular on top of LineAO, or Mallo et al.'s
    // cylinder-averaged diffuse and specular (`lineao::lighting`).
    var diffuse = 0.0;
    var specular = 0.0;
    for (var s = 0u; s < lighting.count; s++) {
        let light = lighting.lights[s];
        let lit = illuminated_line(lighting.line_shading, light.xyz, c, t, lighting.shininess);
        diffuse += light.w * lit.x;
        specular += light.w * lighting.ks * lit.y;
    }
    let shaded = select(color, color * (1.0 - lighting.kd + lighting.kd * diffuse), lighting.line_shading == 1u);

    var out: GBuffer;
    out.color = vec4<f32>(shaded, 1.0);
    out.nd = vec4<f32>(n, gbuffer_depth(view_pos, frame.near, frame.far));
    out.zoom = gbuffer_zoom(view_pos, frame.f_px, frame.zoom_unit, is_orthographic());
    out.specular = specular;
    return out;
}
