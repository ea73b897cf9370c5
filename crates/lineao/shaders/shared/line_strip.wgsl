// The fixed-width line's strip and its G-buffer, shared by the lines' rasterized draws
// (`lines.wgsl`) and the lines rasterized in compute (`raster.wgsl`): a point pushed half a line
// width sideways on screen, perpendicular to its vertex tangent's screen direction, and what a
// fragment of the line writes.
#import shared/geometry.wgsl

// Whether the fragments test the slab (`LineRenderer::with_slab`): a `discard` costs the
// rasterizer its early depth test even where it never runs, so it is compiled in only then.
override SLAB: bool = false;

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

// Which point of its cluster's strip a vertex is, and which side: `point` < 0 for a vertex
// past the strip's end, which collapses.
struct StripPosition {
    point: i32,
    side: f32,
}

// The full strip: point v / 2, left then right. Its last vertex is repeated once (a zero-area
// triangle), then every further vertex collapses to one point.
fn full_strip(v: u32, drawn: u32) -> StripPosition {
    let side = select(1.0, -1.0, (v & 1u) != 0u);
    if v < 2u * drawn {
        return StripPosition(i32(v >> 1u), side);
    }
    return StripPosition(select(-1, i32(drawn) - 1, v == 2u * drawn), -1.0);
}

// The first vertex of point k in the alternating strip of a cluster whose bent inner points are
// `bent` (point j at bit j − 1): one vertex a point, two for the first point and each bent one.
fn alternating_start(k: u32, bent: u32) -> u32 {
    if k == 0u {
        return 0u;
    }
    return k + 1u + countOneBits(bent & ((1u << (k - 1u)) - 1u));
}

// The alternating strip: both sides of the first point, then one side per point by turns, both
// sides of bent points and of the last (L0 R0 L1 R2 L3 … for sides L, R, where nothing bends).
// The point of vertex v is the last whose first vertex is at most v: a binary search over the
// mask's prefix counts (a cluster draws at most 25 points: five steps).
fn alternating_strip(v: u32, drawn: u32, bent: u32) -> StripPosition {
    let side = select(1.0, -1.0, (v & 1u) != 0u);
    let vertices = alternating_start(drawn - 1u, bent) + 2u;
    if v < vertices && bent == 0u {
        return StripPosition(i32(clamp(v, 1u, drawn) - 1u), side);
    }
    if v < vertices {
        var lo = 0u;
        var hi = drawn - 1u;
        while lo < hi {
            let mid = (lo + hi + 1u) >> 1u;
            if alternating_start(mid, bent) <= v {
                lo = mid;
            } else {
                hi = mid - 1u;
            }
        }
        return StripPosition(i32(lo), side);
    }
    // The repeat of the last vertex, then the collapsed ones.
    let last = select(1.0, -1.0, ((vertices - 1u) & 1u) != 0u);
    return StripPosition(select(-1, i32(drawn) - 1, v == vertices), last);
}

// The G-buffer of a point of the line at `view_pos` with tangent `view_tangent`; discarded
// outside the slab where the pipeline tests it.
fn line_gbuffer(view_pos: vec3<f32>, view_tangent: vec3<f32>, color: vec3<f32>) -> GBuffer {
    if SLAB && outside_slab(view_pos) {
        discard;
    }
    let t = normalize(view_tangent);
    let c = gbuffer_eye_direction(view_pos, is_orthographic());
    let n = gbuffer_line_normal(t, c);

    // Illuminated lines (paper §3.3): Zöckler's specular on top of LineAO, or Mallo et al.'s
    // cylinder-averaged diffuse and specular (`lineao::lighting`).
    var diffuse = 0.0;
    var specular = 0.0;
    for (var s = 0u; s < light_count(lighting); s++) {
        let light = lighting.lights[s];
        let lit = illuminated_line(line_shading(lighting), light.xyz, c, t, lighting.shininess);
        diffuse += light.w * lit.x;
        specular += light.w * lighting.ks * lit.y;
    }
    let shaded = select(color, color * (1.0 - lighting.kd + lighting.kd * diffuse), line_shading(lighting) == 1u);

    var out: GBuffer;
    out.color = vec4<f32>(shaded, 1.0);
    out.nd = vec4<f32>(n, gbuffer_depth(view_pos, frame.near, frame.far));
    out.zoom = gbuffer_zoom(view_pos, frame.f_px, frame.zoom_unit, is_orthographic());
    out.specular = specular;
    return out;
}
