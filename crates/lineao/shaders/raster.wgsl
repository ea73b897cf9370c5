// Lines rasterized in compute (`lineao::passes::raster`): the culled pieces' quads written into a
// visibility buffer of 64-bit words by `atomicMax`, then resolved into the G-buffer.
//
// `raster` runs an invocation per segment of each listed piece (a workgroup per instance of the
// hardware draw: 8 pieces of 8 segments). A segment's quad is the hardware strip's — its points
// pushed half a line width sideways (`shared/line_strip.wgsl`), the two triangles (L_a, R_a, L_b)
// and (R_a, L_b, R_b) — and each triangle covers the pixels whose centres its edge functions
// hold, in fixed point of 1/256 pixel with the top-left rule (a pixel centre on an edge belongs
// to the triangle whose top or left edge it is). Its depth is the plane of the three NDC depths,
// as a rasterizer interpolates it. The word written is (~depth << 32) | id, so the largest word
// is the nearest fragment and 0 is nothing drawn: `atomicMax` keeps the nearest.
//
// `fs_resolve_depth` writes the depth of every pixel's winner after the early phase, for the
// cull's depth pyramid; `fs_resolve` runs once a pixel, per page, after the late one: it reads the winning id (page, the slot of the piece
// in the page's lists, the segment, the triangle), decodes the segment's quad again,
// interpolates the vertex outputs at the pixel centre with perspective-correct barycentrics and
// writes what the line's fragment would (`line_gbuffer`), and the depth.
#import shared/clusters.wgsl
#import shared/geometry.wgsl
#import shared/line_strip.wgsl
#import shared/pieces.wgsl
#import shared/fullscreen.wgsl

// Which phase's list `size_raster` and `raster` read (0 early, 1 late: `lineao::passes::cull::Phase`).
override PHASE: u32 = 0u;

// The visibility buffer, a word a pixel of the banded viewport (row-major).
@group(3) @binding(0) var<storage, read_write> visibility: array<atomic<u64>>;
// The page's cull state: words 4d + 1 the instances of draw d (`shaders/cull.wgsl`).
@group(3) @binding(1) var<storage, read> cull_state: array<u32>;
// x: the page's index among the geometry's pages.
@group(3) @binding(2) var<uniform> raster_page: vec4<u32>;
// The visibility buffer as the resolve reads it: x the id, y the inverted depth.
@group(3) @binding(3) var<storage, read> resolved: array<vec2<u32>>;
// `raster`'s indirect dispatch for each phase (x, y, 1, unused).
@group(3) @binding(4) var<storage, read_write> raster_dispatch: array<u32>;

// Workgroups per row of the indirect dispatch.
const RASTER_ROW: u32 = 65535u;
// An id: page << PAGE_SHIFT | slot << 4 | segment << 1 | triangle (`lineao::passes::raster`).
const PAGE_SHIFT: u32 = 27u;
const SLOT_MASK: u32 = 0x7fffffu;
// Sub-pixel steps a pixel (8 bits, as Vulkan rasterizers snap vertices).
const SUBPIXELS: f32 = 256.0;

// The instances of this phase's full and coarse draws.
fn phase_instances() -> vec2<u32> {
    return vec2<u32>(cull_state[4u * PHASE + 1u], cull_state[4u * (PHASE + 2u) + 1u]);
}

@compute @workgroup_size(1)
fn size_raster() {
    let n = phase_instances();
    let instances = n.x + n.y;
    raster_dispatch[4u * PHASE] = min(instances, RASTER_ROW);
    raster_dispatch[4u * PHASE + 1u] = (instances + RASTER_ROW - 1u) / RASTER_ROW;
    raster_dispatch[4u * PHASE + 2u] = 1u;
}

// The four corners of segment `k` of `piece` (between its kept points k and k + 1) as the
// strip's vertices 2k .. 2k + 3: L_a, R_a, L_b, R_b.
fn segment_corners(piece: VisiblePiece, k: u32) -> array<VsOut, 4> {
    let a = pulled_point(piece.cluster, kept_point(piece, k));
    let b = pulled_point(piece.cluster, kept_point(piece, k + 1u));
    let sa = point_scalar(a.index);
    let sb = point_scalar(b.index);
    return array<VsOut, 4>(
        line_vertex(a.position, a.tangent, 1.0, sa),
        line_vertex(a.position, a.tangent, -1.0, sa),
        line_vertex(b.position, b.tangent, 1.0, sb),
        line_vertex(b.position, b.tangent, -1.0, sb),
    );
}

// Clip position `clip` in pixels of the banded viewport (y down), as the viewport transform
// puts it.
fn to_pixels(clip: vec4<f32>) -> vec2<f32> {
    let ndc = clip.xy / clip.w;
    let half = 0.5 * frame.viewport;
    return vec2<f32>(fma(ndc.x, half.x, half.x), fma(-ndc.y, half.y, half.y));
}

// Twice the signed area of (a, b, p), in sub-pixels squared: positive where p lies to the
// right of a → b on a screen whose y points down.
fn edge(a: vec2<i32>, b: vec2<i32>, p: vec2<i32>) -> i64 {
    return i64(b.x - a.x) * i64(p.y - a.y) - i64(b.y - a.y) * i64(p.x - a.x);
}

// Whether a → b is a top edge (horizontal, the triangle below it) or a left one (going up),
// for a triangle whose edges run clockwise on screen.
fn top_left(a: vec2<i32>, b: vec2<i32>) -> bool {
    return (a.y == b.y && b.x > a.x) || b.y < a.y;
}

// A triangle set up for the pixel loop: its three edge functions at the first pixel's centre
// (biased by the top-left rule, so a pixel is covered where all three are ≥ 0) and their steps
// a pixel right and a pixel down, in 32 bits (`SMALL_BOX`); the plane of its depth, z = x + y px
// + z py at pixel (px, py); `live` false for a triangle of no area.
struct Triangle {
    e: vec3<i32>,
    dx: vec3<i32>,
    dy: vec3<i32>,
    plane: vec3<f32>,
    live: bool,
}

// The pixels across within which a triangle's edge functions fit 32 bits: relative to the
// box's corner its sub-pixel coordinates stay under 2^14 + 2^8, their products under 2^29.
const SMALL_BOX: i32 = 64;

// The plane of the depths `z` at the pixel positions `f` (pixel centres at integers), as a
// rasterizer's setup computes it from the unsnapped positions.
fn depth_plane(f0: vec2<f32>, f1: vec2<f32>, f2: vec2<f32>, z: vec3<f32>) -> vec3<f32> {
    let d01 = vec3<f32>(f0 - f1, z.x - z.y);
    let d20 = vec3<f32>(f2 - f0, z.z - z.x);
    let one_over_area = 1.0 / (d01.x * d20.y - d20.x * d01.y);
    let dzdx = (d01.z * d20.y - d01.y * d20.z) * one_over_area;
    let dzdy = (d01.x * d20.z - d01.z * d20.x) * one_over_area;
    return vec3<f32>(z.x - (dzdx * f0.x + dzdy * f0.y), dzdx, dzdy);
}

// Triangle (a, b, c) with depths `z` and pixel positions `f`, relative to pixel `origin`'s centre.
fn setup(a: vec2<i32>, b_in: vec2<i32>, c_in: vec2<i32>, f: array<vec2<f32>, 3>, z: vec3<f32>, origin: vec2<i32>) -> Triangle {
    var t: Triangle;
    let o = origin * 256 + 128;
    var b = b_in - o;
    var c = c_in - o;
    let p = a - o;
    let area = (b.x - p.x) * (c.y - p.y) - (b.y - p.y) * (c.x - p.x);
    t.live = area != 0;
    if area < 0 {
        let swap = b;
        b = c;
        c = swap;
    }
    // Edge u → v at the origin (0, 0): (v.x − u.x)(−u.y) − (v.y − u.y)(−u.x).
    let u = array<vec2<i32>, 3>(b, c, p);
    let v = array<vec2<i32>, 3>(c, p, b);
    for (var k = 0u; k < 3u; k++) {
        let d = v[k] - u[k];
        t.e[k] = d.y * u[k].x - d.x * u[k].y - select(1, 0, top_left(u[k], v[k]));
        t.dx[k] = -d.y * 256;
        t.dy[k] = d.x * 256;
    }
    t.plane = depth_plane(f[0], f[1], f[2], z);
    return t;
}

// Writes a covered pixel's fragment: the nearest word wins.
fn write_fragment(x: i32, y: i32, width: i32, depth: f32, id: u32) {
    if depth < 0.0 || depth >= 1.0 {
        return;
    }
    let word = (u64(~bitcast<u32>(depth)) << 32u) | u64(id);
    atomicMax(&visibility[u32(y) * u32(width) + u32(x)], word);
}

// The segment's quad (corners `c`: L_a, R_a, L_b, R_b) written into the visibility buffer as
// `id` (triangle 0: c0 c1 c2, 1: c1 c2 c3), one pass over its box. A quad with a corner at or
// behind the eye plane is left out (the hardware path clips it: the prototype does not).
fn rasterize(c: array<vec4<f32>, 4>, id: u32) {
    if min(min(c[0].w, c[1].w), min(c[2].w, c[3].w)) <= 0.0 {
        return;
    }
    let f = array<vec2<f32>, 4>(to_pixels(c[0]), to_pixels(c[1]), to_pixels(c[2]), to_pixels(c[3]));
    let p = array<vec2<i32>, 4>(
        vec2<i32>(round(f[0] * SUBPIXELS)),
        vec2<i32>(round(f[1] * SUBPIXELS)),
        vec2<i32>(round(f[2] * SUBPIXELS)),
        vec2<i32>(round(f[3] * SUBPIXELS)),
    );
    let z = vec4<f32>(c[0].z / c[0].w, c[1].z / c[1].w, c[2].z / c[2].w, c[3].z / c[3].w);
    let size = vec2<i32>(frame.viewport);
    // The pixels whose centres (256 i + 128) lie in the quad's box, and those of them in the
    // viewport.
    let first = (min(min(p[0], p[1]), min(p[2], p[3])) - 128 + 255) >> vec2<u32>(8u);
    let last = (max(max(p[0], p[1]), max(p[2], p[3])) - 128) >> vec2<u32>(8u);
    let lo = max(first, vec2<i32>(0));
    let hi = min(last, size - 1);
    if any(hi < lo) {
        return;
    }
    // Pixel centres sit at integers for the depth planes.
    let g = array<vec2<f32>, 4>(f[0] - 0.5, f[1] - 0.5, f[2] - 0.5, f[3] - 0.5);
    if any(last - first >= vec2<i32>(SMALL_BOX)) {
        rasterize_large(p[0], p[1], p[2], depth_plane(g[0], g[1], g[2], z.xyz), lo, hi, id);
        rasterize_large(p[1], p[2], p[3], depth_plane(g[1], g[2], g[3], z.yzw), lo, hi, id | 1u);
        return;
    }
    let t0 = setup(p[0], p[1], p[2], array<vec2<f32>, 3>(g[0], g[1], g[2]), z.xyz, lo);
    let t1 = setup(p[1], p[2], p[3], array<vec2<f32>, 3>(g[1], g[2], g[3]), z.yzw, lo);
    var row0 = t0.e;
    var row1 = t1.e;
    for (var y = lo.y; y <= hi.y; y++) {
        var e0 = row0;
        var e1 = row1;
        for (var x = lo.x; x <= hi.x; x++) {
            // A pixel lies in one of them, or in both where the quad folds over itself.
            if t0.live && all(e0 >= vec3<i32>(0)) {
                write_fragment(x, y, size.x, t0.plane.x + t0.plane.y * f32(x) + t0.plane.z * f32(y), id);
            }
            if t1.live && all(e1 >= vec3<i32>(0)) {
                write_fragment(x, y, size.x, t1.plane.x + t1.plane.y * f32(x) + t1.plane.z * f32(y), id | 1u);
            }
            e0 += t0.dx;
            e1 += t1.dx;
        }
        row0 += t0.dy;
        row1 += t1.dy;
    }
}

// A triangle whose box spans SMALL_BOX pixels or more, its edge functions in 64 bits at each
// pixel of the box [lo, hi].
fn rasterize_large(p0: vec2<i32>, p1_in: vec2<i32>, p2_in: vec2<i32>, plane: vec3<f32>, lo: vec2<i32>, hi: vec2<i32>, id: u32) {
    var p1 = p1_in;
    var p2 = p2_in;
    let area = edge(p0, p1, p2);
    if area == 0li {
        return;
    }
    if area < 0li {
        p1 = p2_in;
        p2 = p1_in;
    }
    let bias = vec3<i64>(
        select(-1li, 0li, top_left(p1, p2)),
        select(-1li, 0li, top_left(p2, p0)),
        select(-1li, 0li, top_left(p0, p1)),
    );
    let width = i32(frame.viewport.x);
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            let p = vec2<i32>(x, y) * 256 + 128;
            let e = vec3<i64>(edge(p1, p2, p), edge(p2, p0, p), edge(p0, p1, p)) + bias;
            if all(e >= vec3<i64>(0li)) {
                write_fragment(x, y, width, plane.x + plane.y * f32(x) + plane.z * f32(y), id);
            }
        }
    }
}

@compute @workgroup_size(64)
fn raster(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let instance = group.x + group.y * RASTER_ROW;
    let n = phase_instances();
    if instance >= n.x + n.y {
        return;
    }
    let coarse = instance >= n.x;
    let slot = (instance - select(0u, n.x, coarse)) * PIECES_PER_INSTANCE + local / PIECE_SEGMENTS;
    let segment = local % PIECE_SEGMENTS;
    let piece = visible_piece(slot, coarse);
    if segment + 1u >= kept_points(piece) || !is_selected(piece.cluster) {
        return;
    }
    // Its slot in the page's lists (the late list starts where the early one's room ends).
    let half = arrayLength(&visible_pieces);
    let listed = PHASE * half + select(slot, half - 1u - slot, coarse);
    let id = (raster_page.x << PAGE_SHIFT) | (listed << 4u) | (segment << 1u);
    let q = segment_corners(piece, segment);
    rasterize(array<vec4<f32>, 4>(q[0].clip, q[1].clip, q[2].clip, q[3].clip), id);
}

@vertex
fn vs_resolve(@builtin(vertex_index) v: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(v);
}

struct Resolved {
    @location(0) color: vec4<f32>,
    @location(1) nd: vec4<f32>,
    @location(2) zoom: f32,
    @location(3) specular: f32,
    @builtin(frag_depth) depth: f32,
}

// Twice the signed area of (a, b, p) in pixels.
fn edge_f(a: vec2<f32>, b: vec2<f32>, p: vec2<f32>) -> f32 {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

@fragment
fn fs_resolve(@builtin(position) at: vec4<f32>) -> Resolved {
    let pixel = vec2<u32>(at.xy);
    let word = resolved[pixel.y * u32(frame.viewport.x) + pixel.x];
    if word.y == 0u || (word.x >> PAGE_SHIFT) != raster_page.x {
        discard;
    }
    let id = word.x;
    let piece = listed_piece(visible_pieces[(id >> 4u) & SLOT_MASK]);
    let q = segment_corners(piece, (id >> 1u) & 7u);
    let first = id & 1u;
    let v = array<VsOut, 3>(q[first], q[first + 1u], q[first + 2u]);
    // Screen barycentrics at the pixel's centre, then divided by each corner's w.
    let s = array<vec2<f32>, 3>(to_pixels(v[0].clip), to_pixels(v[1].clip), to_pixels(v[2].clip));
    let p = at.xy;
    let screen = vec3<f32>(edge_f(s[1], s[2], p), edge_f(s[2], s[0], p), edge_f(s[0], s[1], p));
    var b = screen / vec3<f32>(v[0].clip.w, v[1].clip.w, v[2].clip.w);
    b /= b.x + b.y + b.z;
    let view_pos = b.x * v[0].view_pos + b.y * v[1].view_pos + b.z * v[2].view_pos;
    let tangent = b.x * v[0].view_tangent + b.y * v[1].view_tangent + b.z * v[2].view_tangent;
    var color = b.x * v[0].color + b.y * v[1].color + b.z * v[2].color;
    if frame.color_mode == 3u {
        color = piece_color(piece.stride, piece.left);
    }
    let g = line_gbuffer(view_pos, tangent, color);
    return Resolved(g.color, g.nd, g.zoom, g.specular, bitcast<f32>(~word.y));
}

// The depth alone of every page's nearest fragment (after the early phase: what the cull's
// depth pyramid is built from).
@fragment
fn fs_resolve_depth(@builtin(position) at: vec4<f32>) -> Resolved {
    let pixel = vec2<u32>(at.xy);
    let word = resolved[pixel.y * u32(frame.viewport.x) + pixel.x];
    if word.y == 0u {
        discard;
    }
    return Resolved(vec4<f32>(0.0), vec4<f32>(0.0), 0.0, 0.0, bitcast<f32>(~word.y));
}
