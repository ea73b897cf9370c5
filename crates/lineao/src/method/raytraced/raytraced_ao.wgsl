// Ray-traced ambient occlusion, progressive: per geometry pixel `frame_rays` cosine-weighted
// rays from the CPU truth's scrambled Sobol' sequence (rays first_ray .. first_ray + frame_rays),
// traced through the scene's BVH (`lineao::ray_scene`) against rounded cones and triangles, and
// added to the pixel's running sums of the rays' values and of their squares; `ao` = sum / rays,
// every geometry pixel of a picture having traced first_ray + frame_rays rays. The origin, its
// own segment, the buried test and both falloffs are `lineao::truth`'s, step by step, in f32 relative to the ray's
// origin (the CPU truth is f64). The own segment and the buried test are found on a picture's
// first frame and kept for the frames that continue it.
//
// The scene is read from textures (`lineao::ray_scene` says why), and each pipeline is
// specialized by the `override` flags below: lavapipe runs both sides of every branch, so what
// a frame cannot need is compiled out, not branched around.
#import shared/cone.wgsl
#import shared/nd.wgsl
#import shared/view.wgsl

// Fixed-width lines, radius line_half · max(−z_view, near) (orthographic: line_half); else tubes.
override LINES: bool = true;
// The scene has triangles.
override TRIANGLES: bool = true;
// The vertices carry per-vertex tube radii.
override RADII: bool = false;
// Linear falloff: rays look for the nearest hit; else for any hit (binary).
override NEAREST: bool = false;
// A picture's first frame: find each pixel's own segment and whether its origin is buried.
override START: bool = true;
// Tube pixels find their own segment too (the denoiser's "same tube"; rays ignore it).
override TUBE_OWN: bool = false;

// Keep in sync with `lineao::method::raytraced::TraceUniform`.
struct Trace {
    view: ViewParams,
    inv_view: mat4x4<f32>,
    // The view matrix's third row: z_view(p) = dot(view_z.xyz, p) + view_z.w.
    view_z: vec4<f32>,
    frame_rays: u32,
    first_ray: u32,
    seed: u32,
    distance: f32,
    epsilon: f32,
    line_half: f32,
    tube_radius: f32,
    // The largest tube radius (per vertex or the settings'): what node boxes grow by.
    max_radius: f32,
    guard: u32,
    node_count: u32,
    // Where the streamline starts begin in `words`.
    starts_at: u32,
    streamlines: u32,
    // log2 of the widths of the scene's textures: nodes, vertices, words, triangles.
    shifts: vec4<u32>,
    width: u32,
    height: u32,
}

@group(0) @binding(0) var<uniform> trace: Trace;
@group(0) @binding(1) var nd0: texture_2d<f32>;
@group(0) @binding(2) var ao_out: texture_storage_2d<r32float, write>;
// Per pixel of the guard-banded frame: the sums of the rays' values and of their squares (f32
// bits), the own segment's first vertex (NONE for none) and whether the origin is buried.
@group(0) @binding(3) var<storage, read_write> accumulation: array<vec4<u32>>;
// The scene (`lineao::ray_scene`): two texels per node, one per vertex (xyz, tube radius), one
// word per primitive reference and streamline start, one texel per triangle.
@group(0) @binding(4) var nodes: texture_2d_array<u32>;
@group(0) @binding(5) var vertices: texture_2d_array<u32>;
@group(0) @binding(6) var words: texture_2d_array<u32>;
@group(0) @binding(7) var triangles: texture_2d_array<u32>;

const TRIANGLE_BIT: u32 = 0x80000000u;
const NO_HIT: f32 = 3.0e38;
const STACK: u32 = 48u;

// Texel i of a texture whose square layers are 2^shift wide: (x, y, layer).
fn texel(i: u32, shift: u32) -> vec3<u32> {
    let mask = (1u << shift) - 1u;
    return vec3<u32>(i & mask, (i >> shift) & mask, i >> (2u * shift));
}

fn word(i: u32) -> u32 {
    let at = texel(i, trace.shifts.z);
    return textureLoad(words, at.xy, at.z, 0).x;
}

// Vertex v: its position and, with RADII, its tube radius (≤ 0: the settings').
fn vertex4(v: u32) -> vec4<f32> {
    let at = texel(v, trace.shifts.y);
    return bitcast<vec4<f32>>(textureLoad(vertices, at.xy, at.z, 0));
}

fn vertex(v: u32) -> vec3<f32> {
    return vertex4(v).xyz;
}

// ---- The sample sequence (`lineao::truth::sequence`, bit for bit) ----

fn hash(x: u32) -> u32 {
    let state = x * 747796405u + 2891336453u;
    let w = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (w >> 22u) ^ w;
}

fn pixel_seed(x: i32, y: i32, seed: u32) -> u32 {
    return hash(seed ^ hash(bitcast<u32>(x) + hash(bitcast<u32>(y))));
}

fn laine_karras(x0: u32, seed: u32) -> u32 {
    var x = x0 + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    return reverseBits(laine_karras(reverseBits(x), seed));
}

fn sobol_2d(index: u32) -> vec2<u32> {
    var y = 0u;
    var v = 1u << 31u;
    var i = index;
    while i != 0u {
        if (i & 1u) != 0u {
            y ^= v;
        }
        v ^= v >> 1u;
        i >>= 1u;
    }
    return vec2<u32>(reverseBits(index), y);
}

fn sample_2d(index: u32, seed: u32) -> vec2<f32> {
    let s = sobol_2d(index);
    let sx = hash(seed);
    let sy = hash(sx);
    let scale = 1.0 / 4294967296.0;
    return vec2<f32>(f32(nested_uniform_scramble(s.x, sx)), f32(nested_uniform_scramble(s.y, sy))) * scale;
}

fn cosine_direction(u: vec2<f32>, n: vec3<f32>) -> vec3<f32> {
    let a = 2.0 * u.x - 1.0;
    let b = 2.0 * u.y - 1.0;
    var disk = vec2<f32>(0.0);
    let quarter = 0.7853981633974483;
    if a != 0.0 || b != 0.0 {
        var r: f32;
        var phi: f32;
        if abs(a) > abs(b) {
            r = a;
            phi = quarter * (b / a);
        } else {
            r = b;
            phi = 2.0 * quarter - quarter * (a / b);
        }
        disk = vec2<f32>(r * cos(phi), r * sin(phi));
    }
    let z = sqrt(max(1.0 - dot(disk, disk), 0.0));
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let aa = -1.0 / (sign + n.z);
    let bb = n.x * n.y * aa;
    let t = vec3<f32>(1.0 + sign * n.x * n.x * aa, sign * bb, -sign * n.x);
    let bt = vec3<f32>(bb, sign + n.y * n.y * aa, -n.y);
    return normalize(t * disk.x + bt * disk.y + n * z);
}

// ---- Primitives (`lineao::truth::primitive`) ----

// A segment's cone: its ends and their radii.
struct Cone {
    a: vec3<f32>,
    b: vec3<f32>,
    ra: f32,
    rb: f32,
}

// The radius at vertex `a` (position xyz, tube radius w).
fn radius_at(a: vec4<f32>) -> f32 {
    if LINES {
        if trace.view.orthographic != 0u {
            return trace.line_half;
        }
        return trace.line_half * max(-(dot(trace.view_z.xyz, a.xyz) + trace.view_z.w), trace.view.near);
    }
    if RADII && a.w > 0.0 {
        return a.w;
    }
    return trace.tube_radius;
}

fn cone(v: u32) -> Cone {
    let a = vertex4(v);
    let b = vertex4(v + 1u);
    return Cone(a.xyz, b.xyz, radius_at(a), radius_at(b));
}

// The nearest hit of ro + t rd with t in (0, t_max), or NO_HIT; `ro` is 0 (the cone is given
// relative to the ray's origin). Every root counts: the ray may start inside the cone.
fn intersect_cone(rd: vec3<f32>, pa: vec3<f32>, pb: vec3<f32>, ra: f32, rb: f32, t_max: f32) -> f32 {
    let c = cone_terms(vec3<f32>(0.0), rd, pa, pb, ra, rb);
    var best = NO_HIT;
    if c.d2 > 0.0 && c.h >= 0.0 && c.k2 != 0.0 {
        let s = sqrt(c.h);
        for (var i = 0; i < 2; i++) {
            let t = (select(s, -s, i == 0) - c.k1) / c.k2;
            let y = c.m1 - ra * c.rr + t * c.m2;
            if y > 0.0 && y < c.d2 && t > 0.0 && t < t_max && t < best {
                best = t;
            }
        }
    }
    for (var e = 0; e < 2; e++) {
        let m = select(c.m6, c.m3, e == 0);
        let c2 = select(c.m7, c.m5, e == 0);
        let r = select(rb, ra, e == 0);
        let h = m * m - c2 + r * r;
        if h >= 0.0 {
            let s = sqrt(h);
            for (var i = 0; i < 2; i++) {
                let t = -m + select(s, -s, i == 0);
                if t > 0.0 && t < t_max && t < best {
                    best = t;
                }
            }
        }
    }
    return best;
}

// Möller–Trumbore with the ray at the origin.
fn intersect_triangle(rd: vec3<f32>, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, t_max: f32) -> f32 {
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let p = cross(rd, e2);
    let det = dot(e1, p);
    if abs(det) < 1e-30 {
        return NO_HIT;
    }
    let inv = 1.0 / det;
    let s = -v0;
    let u = dot(s, p) * inv;
    if u < 0.0 || u > 1.0 {
        return NO_HIT;
    }
    let q = cross(s, e1);
    let w = dot(rd, q) * inv;
    if w < 0.0 || u + w > 1.0 {
        return NO_HIT;
    }
    let t = dot(e2, q) * inv;
    return select(NO_HIT, t, t > 0.0 && t < t_max);
}

// Signed distance from p to the cone (negative inside).
fn cone_distance(p: vec3<f32>, c: Cone) -> f32 {
    let ba = c.b - c.a;
    let len = sqrt(dot(ba, ba));
    if abs(c.ra - c.rb) >= len {
        if c.ra >= c.rb {
            return distance(p, c.a) - c.ra;
        }
        return distance(p, c.b) - c.rb;
    }
    let axis = ba / len;
    let along = dot(p - c.a, axis);
    let across = length(p - c.a - along * axis);
    let sin_t = (c.ra - c.rb) / len;
    let cos_t = sqrt(1.0 - sin_t * sin_t);
    let k = -sin_t * across + cos_t * along;
    if k < 0.0 {
        return distance(p, c.a) - c.ra;
    }
    if k > len * cos_t {
        return distance(p, c.b) - c.rb;
    }
    return along * sin_t + across * cos_t - c.ra;
}

// ---- The pixel's own segment (`Origin` in `lineao::truth`) ----

struct Own {
    // The segment's first vertex, or 0xffffffff for none.
    v: u32,
    // Its streamline's vertices [first, end).
    first: u32,
    end: u32,
    // Its axis point nearest to the pixel's position.
    c: vec3<f32>,
}

// Whether a ray from `own`'s surface ignores segment v: the same streamline, and a neighbour or
// a segment still holding the axis point (a tight bend).
// `c` is segment v's cone.
fn skips(own: Own, v: u32, c: Cone) -> bool {
    if own.v == 0xffffffffu || v < own.first || v >= own.end {
        return false;
    }
    if max(v, own.v) - min(v, own.v) <= 1u {
        return true;
    }
    return cone_distance(own.c, c) < 0.0;
}

// The streamline holding vertex v: its [first, end) by binary search over the starts.
fn streamline_of(v: u32) -> vec2<u32> {
    var lo = 0u;
    var hi = trace.streamlines;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if word(trace.starts_at + mid) <= v {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return vec2<u32>(word(trace.starts_at + lo), word(trace.starts_at + lo + 1u));
}

// ---- Traversal ----

// How far a node's box grows: the largest cone radius inside it.
fn box_growth(lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    if !LINES {
        return trace.max_radius;
    }
    if trace.view.orthographic != 0u {
        return trace.line_half;
    }
    // The largest −z_view over the box is at a corner: each coordinate where −row · p is largest.
    let row = trace.view_z.xyz;
    let depth = -(dot(min(row * lo, row * hi), vec3<f32>(1.0)) + trace.view_z.w);
    // A hair more for the rounding of the box's f32 corners.
    return trace.line_half * max(depth, trace.view.near) * 1.0001;
}

struct Node {
    lo: vec3<f32>,
    hi: vec3<f32>,
    first: u32,
    count: u32,
}

fn node(n: u32) -> Node {
    let at = texel(2u * n, trace.shifts.x);
    // Both texels share a row: the width is even.
    let a = textureLoad(nodes, at.xy, at.z, 0);
    let b = textureLoad(nodes, at.xy + vec2<u32>(1u, 0u), at.z, 0);
    let lo = bitcast<vec3<f32>>(a.xyz);
    let hi = bitcast<vec3<f32>>(b.xyz);
    let g = box_growth(lo, hi);
    return Node(lo - g, hi + g, a.w, b.w);
}

// The ray's entry into the box before t_max (relative to the ray's origin ro), or NO_HIT.
fn slab(n: Node, ro: vec3<f32>, inv: vec3<f32>, t_max: f32) -> f32 {
    let a = (n.lo - ro) * inv;
    let b = (n.hi - ro) * inv;
    let t0 = max(max(max(min(a.x, b.x), min(a.y, b.y)), min(a.z, b.z)), 0.0);
    let t1 = min(min(min(max(a.x, b.x), max(a.y, b.y)), max(a.z, b.z)), t_max);
    return select(NO_HIT, t0, t0 <= t1);
}

fn in_box(n: Node, p: vec3<f32>, margin: f32) -> bool {
    return all(p >= n.lo - margin) && all(p <= n.hi + margin);
}

// What a traversal looks for.
const RAY_ANY: u32 = 0u;
const RAY_NEAREST: u32 = 1u;
const INSIDE: u32 = 2u;
const OWN: u32 = 3u;

struct Query {
    mode: u32,
    // Rays: origin and unit direction; point queries: the point in `ro`.
    ro: vec3<f32>,
    rd: vec3<f32>,
    // Rays: the reach; OWN: the footprint.
    t_max: f32,
}

struct Found {
    // Rays: the nearest t (NO_HIT for none); INSIDE: 0 when inside; OWN: the least distance.
    t: f32,
    // OWN: the segment's first vertex.
    v: u32,
}

fn node_entry(q: Query, n: Node, inv: vec3<f32>, best: f32) -> f32 {
    if q.mode <= RAY_NEAREST {
        return slab(n, q.ro, inv, best);
    }
    let margin = select(0.0, q.t_max, q.mode == OWN);
    return select(NO_HIT, 0.0, in_box(n, q.ro, margin));
}

fn traverse(q: Query, own: Own) -> Found {
    var found = Found(select(NO_HIT, q.t_max, q.mode <= RAY_NEAREST), 0xffffffffu);
    if trace.node_count == 0u {
        return found;
    }
    let inv = 1.0 / q.rd;
    var stack: array<u32, STACK>;
    var top = 0u;
    var current = 0u;
    if node_entry(q, node(0u), inv, found.t) == NO_HIT {
        found.t = select(found.t, NO_HIT, q.mode <= RAY_NEAREST);
        return found;
    }
    loop {
        let n = node(current);
        var descend = false;
        if n.count > 0u {
            for (var k = 0u; k < n.count; k++) {
                let r = word(n.first + k);
                if TRIANGLES && (r & TRIANGLE_BIT) != 0u {
                    if q.mode > RAY_NEAREST {
                        continue;
                    }
                    let at = texel(r & ~TRIANGLE_BIT, trace.shifts.w);
                    let t3 = textureLoad(triangles, at.xy, at.z, 0).xyz;
                    let v0 = vertex(t3.x) - q.ro;
                    let v1 = vertex(t3.y) - q.ro;
                    let v2 = vertex(t3.z) - q.ro;
                    let t = intersect_triangle(q.rd, v0, v1, v2, found.t);
                    if t != NO_HIT {
                        found.t = t;
                        if q.mode == RAY_ANY {
                            return found;
                        }
                    }
                    continue;
                }
                let c = cone(r);
                if q.mode != OWN && skips(own, r, c) {
                    continue;
                }
                if q.mode <= RAY_NEAREST {
                    let t = intersect_cone(q.rd, c.a - q.ro, c.b - q.ro, c.ra, c.rb, found.t);
                    if t != NO_HIT {
                        found.t = t;
                        if q.mode == RAY_ANY {
                            return found;
                        }
                    }
                } else {
                    let d = cone_distance(q.ro, c);
                    if q.mode == INSIDE && d < 0.0 {
                        found.t = 0.0;
                        return found;
                    }
                    if q.mode == OWN && d < q.t_max && d < found.t {
                        found.t = d;
                        found.v = r;
                    }
                }
            }
        } else {
            let left = current + 1u;
            let right = n.first;
            let dl = node_entry(q, node(left), inv, found.t);
            let dr = node_entry(q, node(right), inv, found.t);
            if dl != NO_HIT && dr != NO_HIT {
                var near = left;
                var far = right;
                if dr < dl {
                    near = right;
                    far = left;
                }
                if top < STACK {
                    stack[top] = far;
                    top++;
                }
                current = near;
                descend = true;
            } else if dl != NO_HIT {
                current = left;
                descend = true;
            } else if dr != NO_HIT {
                current = right;
                descend = true;
            }
        }
        if !descend {
            if top == 0u {
                break;
            }
            top--;
            current = stack[top];
        }
    }
    if q.mode <= RAY_NEAREST && found.t >= q.t_max {
        found.t = NO_HIT;
    }
    return found;
}

// The pixel's origin, from its own segment v (NONE: a surface pixel): where its rays start and
// what they ignore.
struct Origin {
    start: vec3<f32>,
    own: Own,
}

const NONE: u32 = 0xffffffffu;

fn origin(p: vec3<f32>, n: vec3<f32>, v: u32) -> Origin {
    if v == NONE {
        return Origin(p + trace.epsilon * n, Own(NONE, 0u, 0u, vec3<f32>(0.0)));
    }
    let c = cone(v);
    let ba = c.b - c.a;
    let l2 = dot(ba, ba);
    let s = select(clamp(dot(p - c.a, ba) / l2, 0.0, 1.0), 0.0, l2 == 0.0);
    let axis = c.a + ba * s;
    let r = c.ra + (c.rb - c.ra) * s;
    let range = streamline_of(v);
    return Origin(axis + (r + trace.epsilon) * n, Own(v, range.x, range.y, axis));
}

@compute @workgroup_size(8, 8)
fn raytraced_ao(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= trace.width || id.y >= trace.height {
        return;
    }
    let pixel = id.xy;
    let index = pixel.y * trace.width + pixel.x;
    let texel = textureLoad(nd0, vec2<i32>(pixel), 0);
    if nd_is_background(texel) {
        textureStore(ao_out, vec2<i32>(pixel), vec4<f32>(0.0));
        return;
    }
    // (sum, sum of squares, own segment, buried) as bits.
    var state = accumulation[index];
    if trace.frame_rays > 0u {
        // The pixel's world position and normal.
        let depth = linear_depth(trace.view, texel.w);
        let p = (trace.inv_view * vec4<f32>(view_position(trace.view, pixel, depth), 1.0)).xyz;
        let n = normalize((trace.inv_view * vec4<f32>(texel.xyz, 0.0)).xyz);
        if START {
            // A new picture: the pixel's own segment and whether its origin is buried, found once
            // and kept for the frames that continue it.
            var own = NONE;
            if LINES || TUBE_OWN {
                // The segment holding p most deeply, within a pixel's footprint of its surface.
                let footprint = select(depth, 1.0, trace.view.orthographic != 0u) / trace.view.f_px;
                own = traverse(Query(OWN, p, vec3<f32>(1.0), footprint), Own(NONE, 0u, 0u, vec3<f32>(0.0))).v;
            }
            let o = origin(p, n, select(NONE, own, LINES));
            let buried = traverse(Query(INSIDE, o.start, vec3<f32>(1.0), 0.0), o.own).t == 0.0;
            state = vec4<u32>(0u, 0u, own, u32(buried));
        }
        // Tubes start at the surface whether or not they know their segment.
        let o = origin(p, n, select(NONE, state.z, LINES));
        // A buried origin's rays all count 1.
        var sum = f32(trace.frame_rays);
        var squares = sum;
        if state.w == 0u {
            let guard = i32(trace.guard);
            let seed = pixel_seed(i32(pixel.x) - guard, i32(pixel.y) - guard, trace.seed);
            let mode = select(RAY_ANY, RAY_NEAREST, NEAREST);
            sum = 0.0;
            squares = 0.0;
            for (var i = 0u; i < trace.frame_rays; i++) {
                let d = cosine_direction(sample_2d(trace.first_ray + i, seed), n);
                let t = traverse(Query(mode, o.start, d, trace.distance), o.own).t;
                if t != NO_HIT {
                    let value = select(1.0, 1.0 - t / trace.distance, mode == RAY_NEAREST);
                    sum += value;
                    squares += value * value;
                }
            }
        }
        state.x = bitcast<u32>(bitcast<f32>(state.x) + sum);
        state.y = bitcast<u32>(bitcast<f32>(state.y) + squares);
        accumulation[index] = state;
    }
    let rays = trace.first_ray + trace.frame_rays;
    textureStore(ao_out, vec2<i32>(pixel), vec4<f32>(select(0.0, bitcast<f32>(state.x) / f32(rays), rays > 0u)));
}
