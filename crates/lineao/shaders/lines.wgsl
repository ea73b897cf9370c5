// Line renderer: polylines at a fixed pixel width as triangle strips, writing the G-buffer of
// CONTRACT.md (color, ND map, zoom map, specular, hardware depth).
//
// The vertex shader pulls each strip vertex from the clusters (`shared/clusters.wgsl`):
// instance = a cluster, vertex = a position along its strip, which takes every point twice
// (left, right) — the full strip — or, drawn from afar, one side per point by turns but both
// sides of bent points (the alternating strip; `lineao::line_geometry` has the tolerance
// argument).
// It pushes the point half a line width sideways, perpendicular to the screen direction of its
// *vertex* tangent, so consecutive segments share their join corners exactly: joins without
// gaps or overlaps. Vertices past a cluster's strip repeat its last one and then collapse to
// one point: zero-area triangles.
#import shared/clusters.wgsl
#import shared/geometry.wgsl
#import shared/pieces.wgsl

// Whether the fragments test the slab (`LineRenderer::with_slab`): a `discard` costs the
// rasterizer its early depth test even where it never runs, so it is compiled in only then.
override SLAB: bool = false;

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

// A vertex that collapses with every other past its strip's end.
fn collapsed() -> VsOut {
    var out: VsOut;
    out.clip = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    return out;
}

fn strip_vertex(c: Cluster, at: StripPosition) -> VsOut {
    if at.point < 0 || !is_selected(c) {
        return collapsed();
    }
    let q = pulled_point(c, u32(at.point));
    return line_vertex(q.position, q.tangent, at.side, point_scalar(q.index));
}

@vertex
fn vs_full(@builtin(vertex_index) v: u32, @builtin(instance_index) cluster: u32) -> VsOut {
    let c = clusters[cluster];
    return strip_vertex(c, full_strip(v, drawn_points(c)));
}

@vertex
fn vs_alternating(@builtin(vertex_index) v: u32, @builtin(instance_index) cluster: u32) -> VsOut {
    let c = clusters[cluster];
    return strip_vertex(c, alternating_strip(v, drawn_points(c), c.flags >> BENT_SHIFT));
}

// Native 1-px lines (a `LineList`: segment v / 2 of the cluster): the rasterizer's own thin
// lines, the baseline the strip is measured against (`lineao bench`, pass `lines-native-1px`).
// Segments past the cluster's end lie outside the clip volume.
@vertex
fn vs_native(@builtin(vertex_index) v: u32, @builtin(instance_index) cluster: u32) -> VsOut {
    let c = clusters[cluster];
    let segment = v >> 1u;
    if segment + 1u >= drawn_points(c) || !is_selected(c) {
        var out: VsOut;
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    let q = pulled_point(c, segment + (v & 1u));
    return line_vertex(q.position, q.tangent, 0.0, point_scalar(q.index));
}

struct Piece {
    cluster: Cluster,
    at: StripPosition,
    stride: u32,
    left: u32,
}

// Vertex `v` of instance `instance` of the full (or `coarse`) pieces: block v / `stride` is a
// listed piece's full strip through the points it keeps (the same triangles as the cluster's
// full strip for a full piece, so the culled lines draw its pixels exactly; a kept point keeps
// its own tangent, so a coarse piece's corners there are the full strip's) and then a repeat
// of its last vertex and of the next block's first, so that the blocks' triangles are their own
// strips' (each block starts at an even vertex: the same vertex order in every triangle) and
// those between them have zero area. A piece keeping fewer points collapses the rest.
fn piece_vertex(v: u32, instance: u32, coarse: bool) -> Piece {
    let stride = select(PIECE_STRIDE, COARSE_PIECE_STRIDE, coarse);
    let block = v / stride;
    var k = v % stride;
    var slot = instance * PIECES_PER_INSTANCE + block;
    if k == stride - 1u && block + 1u < PIECES_PER_INSTANCE {
        // The next block's first vertex.
        slot += 1u;
        k = 0u;
    }
    let piece = visible_piece(slot, coarse);
    // Its strip's last vertex (the repeat after it, or the end of the instance).
    let at = full_strip(min(k, stride - 3u), kept_points(piece));
    let point = select(-1, i32(kept_point(piece, u32(max(at.point, 0)))), at.point >= 0);
    return Piece(piece.cluster, StripPosition(point, at.side), piece.stride, piece.left);
}

// A piece's strip vertex, colored by its level in color mode 3.
fn piece_strip_vertex(piece: Piece) -> VsOut {
    var out = strip_vertex(piece.cluster, piece.at);
    if frame.color_mode == 3u {
        out.color = piece_color(piece.stride, piece.left);
    }
    return out;
}

@vertex
fn vs_piece(@builtin(vertex_index) v: u32, @builtin(instance_index) instance: u32) -> VsOut {
    return piece_strip_vertex(piece_vertex(v, instance, false));
}

@vertex
fn vs_piece_octants(@builtin(vertex_index) v: u32, @builtin(instance_index) instance: u32) -> VsOutOctants {
    let piece = piece_vertex(v, instance, false);
    return with_point_octants(piece_strip_vertex(piece), piece.cluster, piece.at);
}

@vertex
fn vs_piece_coarse(@builtin(vertex_index) v: u32, @builtin(instance_index) instance: u32) -> VsOut {
    return piece_strip_vertex(piece_vertex(v, instance, true));
}

@vertex
fn vs_piece_coarse_octants(@builtin(vertex_index) v: u32, @builtin(instance_index) instance: u32) -> VsOutOctants {
    let piece = piece_vertex(v, instance, true);
    return with_point_octants(piece_strip_vertex(piece), piece.cluster, piece.at);
}

fn with_point_octants(b: VsOut, c: Cluster, at: StripPosition) -> VsOutOctants {
    var octants = array<vec4<f32>, 2>(vec4<f32>(1.0), vec4<f32>(1.0));
    if at.point >= 0 {
        octants = point_octants(c.first + u32(at.point));
    }
    return VsOutOctants(b.clip, b.view_pos, b.view_tangent, b.color, octants[0], octants[1]);
}

// The strips with the points' octant visibilities (object-space AO), for `fs_octants`.
@vertex
fn vs_full_octants(@builtin(vertex_index) v: u32, @builtin(instance_index) cluster: u32) -> VsOutOctants {
    let c = clusters[cluster];
    let at = full_strip(v, drawn_points(c));
    return with_point_octants(strip_vertex(c, at), c, at);
}

@vertex
fn vs_alternating_octants(@builtin(vertex_index) v: u32, @builtin(instance_index) cluster: u32) -> VsOutOctants {
    let c = clusters[cluster];
    let at = alternating_strip(v, drawn_points(c), c.flags >> BENT_SHIFT);
    return with_point_octants(strip_vertex(c, at), c, at);
}

@fragment
fn fs_main(in: VsOut) -> GBuffer {
    return line_gbuffer(in.view_pos, in.view_tangent, in.color);
}

@fragment
fn fs_octants(in: VsOutOctants) -> GBufferOctants {
    return with_octants(line_gbuffer(in.view_pos, in.view_tangent, in.color), in.octants_lo, in.octants_hi);
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
