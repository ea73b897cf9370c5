// Tube renderer: every segment a ray-cast rounded cone (two spheres of the ends' radii and the
// cone tangent to both; a capsule for one radius) on a billboard that bounds its projection,
// writing true depth, the surface's normal and the G-buffer of docs/reference.md. Overlapping
// billboards at the joints each ray-cast their own segment and the depth test keeps the nearest
// hit, so a polyline renders as the exact union of its segments' solids: seamless joints.
// The vertex shader pulls the segments from the clusters (`shared/clusters.wgsl`): instance = a
// cluster, six vertices (two triangles) per segment; culled, instance = visible pieces
// (`shared/pieces.wgsl`). `lineao::passes::tubes` documents it; `lineao::reference::tubes` is
// the CPU side.
#import shared/billboard.wgsl
#import shared/clusters.wgsl
#import shared/cone.wgsl
#import shared/geometry.wgsl
#import shared/pieces.wgsl

// Whether the fragment shader writes the octant visibilities (`fs_tube_octants`): without, the
// vertices neither read nor pass them (a uniform branch runs both sides on a CPU rasterizer).
override OCTANTS: bool = true;

struct TubeOut {
    @builtin(position) clip: vec4<f32>,
    // View-space ends and their radii, world units.
    @location(0) @interpolate(flat) a: vec3<f32>,
    @location(1) @interpolate(flat) b: vec3<f32>,
    @location(2) @interpolate(flat) radii: vec2<f32>,
    // Base colors and octant visibilities of both ends, mixed along the segment per pixel.
    @location(3) @interpolate(flat) color_a: vec3<f32>,
    @location(4) @interpolate(flat) color_b: vec3<f32>,
    @location(5) @interpolate(flat) octants_a_lo: vec4<f32>,
    @location(6) @interpolate(flat) octants_a_hi: vec4<f32>,
    @location(7) @interpolate(flat) octants_b_lo: vec4<f32>,
    @location(8) @interpolate(flat) octants_b_hi: vec4<f32>,
    // The pixel's ray in view space, unnormalized: affine in screen space for either
    // projection, so the rasterizer interpolates it exactly.
    @location(9) ray_origin: vec3<f32>,
    @location(10) ray_direction: vec3<f32>,
}

// What a tube fragment reads of `TubeOut` but its octants (read only where written: fewer
// inputs, less set-up per triangle).
struct TubeIn {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) a: vec3<f32>,
    @location(1) @interpolate(flat) b: vec3<f32>,
    @location(2) @interpolate(flat) radii: vec2<f32>,
    @location(3) @interpolate(flat) color_a: vec3<f32>,
    @location(4) @interpolate(flat) color_b: vec3<f32>,
    @location(9) ray_origin: vec3<f32>,
    @location(10) ray_direction: vec3<f32>,
}

// Corner `corner` (0..3 of the billboard: (−, −), (−, +), (+, −), (+, +)) of the segment from
// `a` to `b` (world points with unit tangents `ta`, `tb`) of radii `ra`, `rb` (world units);
// `whole_a`: a starts its run, so no segment before holds its sphere.
fn tube_vertex(corner: u32, a_world: PulledPoint, b_world: PulledPoint, ra: f32, rb: f32, whole_a: bool) -> TubeOut {
    var out: TubeOut;
    let a = (frame.view * vec4<f32>(a_world.position, 1.0)).xyz;
    let b = (frame.view * vec4<f32>(b_world.position, 1.0)).xyz;
    out.a = a;
    out.b = b;
    out.radii = vec2<f32>(ra, rb);
    out.color_a = base_color(a_world.tangent, point_scalar(a_world.index));
    out.color_b = base_color(b_world.tangent, point_scalar(b_world.index));
    if OCTANTS {
        let octants_a = point_octants(a_world.index);
        let octants_b = point_octants(b_world.index);
        out.octants_a_lo = octants_a[0];
        out.octants_a_hi = octants_a[1];
        out.octants_b_lo = octants_b[0];
        out.octants_b_hi = octants_b[1];
    }
    // An end behind the eye: a degenerate billboard (outside the clip volume).
    if behind_eye(a) || behind_eye(b) {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    // The billboard (`shared/billboard.wgsl`): a rectangle along the segment around what it
    // must show — end b's sphere, the body, and end a's sphere where the run starts at a (else
    // the segment before shows that sphere: a billboard reaching a sphere's radius behind each
    // end made every segment's overlap its neighbours' twice, 1.2× the fragments of a tube
    // frame, lavapipe, 1 M vertices) — at the solid's nearest depth (the fragment shader
    // writes the true depth, never nearer).
    let bb = billboard(a, b, ra, rb);
    let along = select(vec2<f32>(1.0, 0.0), normalize(bb.pb - bb.pa), distance(bb.pa, bb.pb) > 1e-6);
    let length_px = dot(bb.pb - bb.pa, along);
    var reach_a = vec2<f32>(bb.reach_a);
    if !whole_a {
        reach_a = body_reach(a, b, ra, rb, along, bb.reach_a);
    }
    let back = min(-reach_a.x, length_px - bb.reach_b);
    let front = max(reach_a.y, length_px + bb.reach_b);
    let across = vec2<f32>(-along.y, along.x) * max(bb.reach_a, bb.reach_b);
    let end = (corner & 2u) != 0u;
    let side = select(-1.0, 1.0, (corner & 1u) != 0u);
    let pixel = bb.pa + along * select(back, front, end) + across * side;
    let ndc = (pixel / frame.viewport - 0.5) * vec2<f32>(2.0, -2.0);
    out.clip = vec4<f32>(ndc, bb.depth, 1.0);
    let near = frame.inv_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = frame.inv_proj * vec4<f32>(ndc, 1.0, 1.0);
    out.ray_origin = near.xyz / near.w;
    out.ray_direction = far.xyz / far.w - out.ray_origin;
    return out;
}

// Corner `corner` (0..5: two triangles) of the tube between points `first` and `last` of
// cluster `c`'s strip (consecutive, or kept at a level of detail: `last` keeps its own
// tangent); `drawn`: whether there is such a segment, else it lies outside the clip volume.
fn segment_vertex(c: Cluster, first: u32, last: u32, corner: u32, drawn: bool) -> TubeOut {
    if !drawn || !is_selected(c) {
        var out: TubeOut;
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    let corners = array<u32, 6>(0u, 1u, 2u, 2u, 1u, 3u);
    let a = pulled_point(c, first);
    let b = pulled_point(c, last);
    let ra = point_radius(a.index);
    let rb = point_radius(b.index);
    let radius_a = select(frame.tube_radius, ra, ra > 0.0);
    let radius_b = select(frame.tube_radius, rb, rb > 0.0);
    let whole_a = first == 0u && (c.flags & JOINS_PREVIOUS) == 0u;
    return tube_vertex(corners[corner], a, b, radius_a, radius_b, whole_a);
}

// Vertex v of a cluster's tubes: segment v / 6, two triangles of its billboard's corners.
@vertex
fn vs_tube(@builtin(vertex_index) v: u32, @builtin(instance_index) cluster: u32) -> TubeOut {
    let c = clusters[cluster];
    let segment = v / 6u;
    return segment_vertex(c, segment, segment + 1u, v % 6u, segment + 1u < drawn_points(c));
}

// Vertex v of an instance of the culled tubes (`lineao::passes::cull`): PIECES_PER_INSTANCE
// listed pieces of list `coarse`, six vertices for each segment between a piece's kept points,
// of which a full piece has PIECE_SEGMENTS and a coarse one (at most every second point kept)
// half as many. In color mode 3 the piece's level, or why the frozen cull left it out.
fn piece_tube_vertex(v: u32, instance: u32, coarse: bool) -> TubeOut {
    let per_piece = 6u * select(PIECE_SEGMENTS, PIECE_SEGMENTS / 2u, coarse);
    let piece = visible_piece(instance * PIECES_PER_INSTANCE + v / per_piece, coarse);
    let k = v % per_piece;
    let segment = k / 6u;
    let drawn = segment + 1u < kept_points(piece);
    var out = segment_vertex(piece.cluster, kept_point(piece, segment), kept_point(piece, segment + 1u), k % 6u, drawn);
    if frame.color_mode == 3u {
        out.color_a = piece_color(piece.stride, piece.left);
        out.color_b = out.color_a;
    }
    return out;
}

@vertex
fn vs_tube_piece(@builtin(vertex_index) v: u32, @builtin(instance_index) instance: u32) -> TubeOut {
    return piece_tube_vertex(v, instance, false);
}

@vertex
fn vs_tube_piece_coarse(@builtin(vertex_index) v: u32, @builtin(instance_index) instance: u32) -> TubeOut {
    return piece_tube_vertex(v, instance, true);
}

// The first hit of the ray ro + t rd (|rd| = 1) with the rounded cone between spheres (pa, ra)
// and (pb, rb): (t, outward unit normal), or t < 0 for none. The body is the quadratic
// k2 t² + 2 k1 t + k0 = 0 (either root may be the body's: squaring admits the mirrored cone
// beyond the apex); the solid is convex, so its entry is the smallest t among the valid body
// roots and the end spheres' entries (the terms: `shared/cone.wgsl`). Derived in
// `lineao::reference::tubes::intersect_rounded_cone`; keep the two in sync.
fn intersect_rounded_cone(ro: vec3<f32>, rd: vec3<f32>, pa: vec3<f32>, pb: vec3<f32>, ra: f32, rb: f32) -> vec4<f32> {
    let c = cone_terms(ro, rd, pa, pb, ra, rb);
    // x: t of the best hit so far (none: +inf), yzw: its normal.
    var best = vec4<f32>(1e30, 0.0, 0.0, 0.0);
    if c.d2 > 0.0 && c.h >= 0.0 && c.k2 != 0.0 {
        let roots = array<f32, 2>((-sqrt(c.h) - c.k1) / c.k2, (sqrt(c.h) - c.k1) / c.k2);
        // For k2 > 0 the first root enters the infinite cone, which holds the solid: on the
        // body, it is the entry (the common case, decided without the spheres).
        let y0 = c.m1 - ra * c.rr + roots[0] * c.m2;
        if c.k2 > 0.0 && y0 > 0.0 && y0 < c.d2 {
            return vec4<f32>(roots[0], normalize(c.d2 * (c.oa + roots[0] * rd) - c.ba * y0));
        }
        for (var i = 0; i < 2; i++) {
            let t = roots[i];
            let y = c.m1 - ra * c.rr + t * c.m2;
            if y > 0.0 && y < c.d2 && t < best.x {
                best = vec4<f32>(t, normalize(c.d2 * (c.oa + t * rd) - c.ba * y));
            }
        }
    }
    // The end spheres' entries (a sphere holding the other leaves no body).
    let h1 = c.m3 * c.m3 - c.m5 + ra * ra;
    if h1 > 0.0 {
        let t = -c.m3 - sqrt(h1);
        if t < best.x {
            best = vec4<f32>(t, (c.oa + t * rd) / ra);
        }
    }
    let h2 = c.m6 * c.m6 - c.m7 + rb * rb;
    if h2 > 0.0 {
        let t = -c.m6 - sqrt(h2);
        if t < best.x {
            best = vec4<f32>(t, (c.ob + t * rd) / rb);
        }
    }
    return select(best, vec4<f32>(-1.0), best.x >= 1e30);
}

struct TubeHit {
    gbuffer: GBuffer,
    // Position along the segment, 0 at a, 1 at b.
    s: f32,
    depth: f32,
}

// The pixel's ray, the hit and its G-buffer; discards a miss, and a hit outside the slab.
fn tube_hit(in: TubeIn) -> TubeHit {
    let ro = in.ray_origin;
    let rd = normalize(in.ray_direction);
    let hit = intersect_rounded_cone(ro, rd, in.a, in.b, in.radii.x, in.radii.y);
    if hit.x < 0.0 {
        discard;
    }
    let p = ro + hit.x * rd;
    if outside_slab(p) {
        discard;
    }
    // Unit, as the ND map wants (an end sphere's (p − c) / r is only within rounding).
    let n = normalize(hit.yzw);
    let ab = in.b - in.a;
    let s = clamp(dot(p - in.a, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);

    // Phong tubes: ambient (what LineAO darkens) and diffuse in the color, specular on top.
    let lit = phong(n, -rd);
    let base = mix(in.color_a, in.color_b, s);
    var out: TubeHit;
    out.gbuffer.color = vec4<f32>(base * (1.0 - lighting.kd + lighting.kd * lit.x), 1.0);
    out.gbuffer.nd = gbuffer_nd(p, n, frame.near, frame.far, is_orthographic());
    out.gbuffer.zoom = gbuffer_zoom(p, frame.f_px, frame.zoom_unit, is_orthographic());
    out.gbuffer.specular = lit.y;
    out.s = s;
    let clip = frame.proj * vec4<f32>(p, 1.0);
    out.depth = clip.z / clip.w;
    return out;
}

struct TubeFragment {
    @builtin(frag_depth) depth: f32,
    @location(0) color: vec4<f32>,
    @location(1) nd: vec4<f32>,
    @location(2) zoom: f32,
    @location(3) specular: f32,
}

struct TubeFragmentOctants {
    @builtin(frag_depth) depth: f32,
    @location(0) color: vec4<f32>,
    @location(1) nd: vec4<f32>,
    @location(2) zoom: f32,
    @location(3) specular: f32,
    @location(4) octants: vec2<u32>,
}

// The hit is never nearer than the billboard's depth (the solid's front), so where the device
// can take that promise (`wgpu::Features::SHADER_EARLY_DEPTH_TEST`) the tube renderer puts
// `@early_depth_test(greater_equal)` on the fragment entries: hidden fragments are dropped before
// they are shaded, though the shader writes its depth.
@fragment
//@conservative_depth
fn fs_tube(in: TubeIn) -> TubeFragment {
    let h = tube_hit(in);
    let g = h.gbuffer;
    return TubeFragment(h.depth, g.color, g.nd, g.zoom, g.specular);
}

@fragment
//@conservative_depth
fn fs_tube_octants(in: TubeOut) -> TubeFragmentOctants {
    let h = tube_hit(TubeIn(in.clip, in.a, in.b, in.radii, in.color_a, in.color_b, in.ray_origin, in.ray_direction));
    let g = with_octants(
        h.gbuffer,
        mix(in.octants_a_lo, in.octants_b_lo, h.s),
        mix(in.octants_a_hi, in.octants_b_hi, h.s),
    );
    return TubeFragmentOctants(h.depth, g.color, g.nd, g.zoom, g.specular, g.octants);
}
