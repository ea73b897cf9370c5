// Line renderer: polylines at a fixed pixel width as triangle strips, writing the G-buffer of
// docs/reference.md (color, ND map, zoom map, specular, hardware depth).
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
#import shared/line_strip.wgsl
#import shared/pieces.wgsl

// The strip's outputs and the octant visibilities, interpolated along and across the line.
struct VsOutOctants {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) view_tangent: vec3<f32>,
    @location(2) color: vec3<f32>,
    @location(3) octants_lo: vec4<f32>,
    @location(4) octants_hi: vec4<f32>,
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
