// Transparent lines (`lineao::passes::transparency`): the K nearest fragments of each pixel kept
// exactly in a K-buffer, those beyond blended into a tail, composited front to back over the
// opaque picture.
//
// Both passes draw every line of opacity > 0 (no depth test: a fragment behind the opaque
// G-buffer's depth is discarded by the shader). `fs_depths` (pass 1) inserts each fragment's
// key (its inverted depth above its nearest point, 0: empty) into its pixel's K slots by
// atomicMax: the largest — nearest — stays, the smaller moves on to the next slot, so the slots
// end up holding the K nearest. `fs_colors` (pass 2, the same fragments again) finds its key
// among the slots and writes its shaded colour and opacity there; a fragment not among them is
// the tail's: blended into a premultiplied sum (`accum`) and a product of transmittances
// (`reveal`). `fs_resolve` sorts the slots of a pixel by depth and composites them front to
// back (one line's overlapping pieces once), then the tail's average colour with the tail's
// coverage, and outputs premultiplied colour and coverage for the "over" blend onto the
// opaque picture.
#import shared/clusters.wgsl
#import shared/geometry.wgsl
#import shared/line_strip.wgsl
#import shared/object_ao.wgsl
#import shared/fullscreen.wgsl

// The K of the K-buffer (`TransparencySettings::layers`).
override LAYERS: u32 = 8u;
// Whether the points carry octant visibilities: each fragment is then darkened by its own
// object-space AO.
override OCTANTS: bool = false;
// The most layers a K-buffer holds (`TransparencySettings::LAYERS`).
const MAX_LAYERS: u32 = 16u;
// A key: the depth, nearest largest, in its high bits (2⁻²⁰ steps of [0, 1]), the point nearest
// the fragment in its low bits (its index on the page, modulo 2¹²).
const POINT_BITS: u32 = 12u;
const POINT_MASK: u32 = 0xfffu;
const DEPTH_STEPS: u32 = 0x100000u;
// Fragments adjacent in depth whose nearest points are this close are one line's pieces
// overlapping (a join, a bend's fold): the line counts once there.
const SAME_LINE: u32 = 2u;

// Keep in sync with `lineao::passes::transparency::LayerUniform`.
struct LayerUniform {
    // Opacity of the selected lines (0 where they are drawn opaque) and of the others (0: hidden).
    alpha: f32,
    context_alpha: f32,
    // The composite's AO strength.
    strength: f32,
    _pad0: u32,
    // The guard-banded size, and the guard band (the resolve's visible pixel + guard).
    size: vec2<u32>,
    guard: vec2<u32>,
}

@group(2) @binding(0) var<uniform> layer: LayerUniform;
@group(2) @binding(1) var<uniform> volume_params: VolumeAoUniform;
@group(3) @binding(0) var<storage, read_write> depths: array<atomic<u32>>;
// Per slot: pack2x16float of (r, g) and of (b, α).
@group(3) @binding(1) var<storage, read_write> colors: array<vec2<u32>>;
@group(3) @binding(2) var<storage, read> volume_table: array<vec4<f32>>;
// The opaque G-buffer's depth: a fragment behind it is hidden. Tested here, before any write,
// rather than by the rasterizer: a depth test after a shader with side effects would let its
// writes through.
@group(3) @binding(3) var opaque_depth: texture_depth_2d;
// The resolve's tail (group 0 there: no geometry is drawn).
@group(0) @binding(0) var tail_accum: texture_2d<f32>;
@group(0) @binding(1) var tail_reveal: texture_2d<f32>;

struct LayerOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) view_tangent: vec3<f32>,
    @location(2) color: vec3<f32>,
    @location(3) @interpolate(flat) alpha: f32,
    @location(4) octants_lo: vec4<f32>,
    @location(5) octants_hi: vec4<f32>,
    // The point index, interpolated along the line: rounded, the point nearest the fragment.
    @location(6) point: f32,
}

// A cluster's opacity in the layers: the selection's or the context's; 0 is not drawn here.
fn layer_alpha(c: Cluster) -> f32 {
    return select(layer.context_alpha, layer.alpha, is_selected(c));
}

// A strip vertex of a cluster whose opacity is not 0 (the others' collapse).
fn layer_vertex(c: Cluster, at: StripPosition) -> LayerOut {
    let alpha = layer_alpha(c);
    var out: LayerOut;
    if at.point < 0 || alpha <= 0.0 {
        out.clip = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        return out;
    }
    let q = pulled_point(c, u32(at.point));
    let b = line_vertex(q.position, q.tangent, at.side, point_scalar(q.index));
    out.clip = b.clip;
    out.view_pos = b.view_pos;
    out.view_tangent = b.view_tangent;
    out.color = b.color;
    out.alpha = alpha;
    out.point = f32(q.index);
    out.octants_lo = vec4<f32>(1.0);
    out.octants_hi = vec4<f32>(1.0);
    if OCTANTS {
        let o = point_octants(c.first + u32(at.point));
        out.octants_lo = o[0];
        out.octants_hi = o[1];
    }
    return out;
}

// The strips `lines.wgsl` draws: the full one (`vs_full`), and the alternating one from afar.
@vertex
fn vs_layer(@builtin(vertex_index) v: u32, @builtin(instance_index) cluster: u32) -> LayerOut {
    let c = clusters[cluster];
    return layer_vertex(c, full_strip(v, drawn_points(c)));
}

@vertex
fn vs_layer_alternating(@builtin(vertex_index) v: u32, @builtin(instance_index) cluster: u32) -> LayerOut {
    let c = clusters[cluster];
    return layer_vertex(c, alternating_strip(v, drawn_points(c), c.flags >> BENT_SHIFT));
}

// Slot `k` of the guard-banded pixel `pixel`.
fn slot(pixel: vec2<u32>, k: u32) -> u32 {
    return (pixel.y * layer.size.x + pixel.x) * LAYERS + k;
}

// The fragment's key: its depth, inverted so that the nearest is the largest and 0 is nothing,
// above its nearest point (what tells a line's own overlapping pieces from another line).
fn key(clip: vec4<f32>, point: f32) -> u32 {
    let depth = clamp(u32(clip.z * f32(DEPTH_STEPS)), 1u, DEPTH_STEPS - 1u);
    return ((DEPTH_STEPS - depth) << POINT_BITS) | (u32(round(point)) & POINT_MASK);
}

// Whether two keys' points are close on the page (modulo 2¹²): one line's pieces.
fn same_line(a: u32, b: u32) -> bool {
    let d = (a - b) & POINT_MASK;
    return min(d, POINT_MASK + 1u - d) <= SAME_LINE;
}

// Whether the fragment at `clip`, `view_pos` is cut by the slab or lies behind the opaque picture.
fn hidden(clip: vec4<f32>, view_pos: vec3<f32>) -> bool {
    return (SLAB && outside_slab(view_pos)) || clip.z >= textureLoad(opaque_depth, vec2<u32>(clip.xy), 0);
}

// What the depths pass reads of `LayerOut` (a device may then interpolate nothing else).
struct DepthIn {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(6) point: f32,
}

@fragment
fn fs_depths(in: DepthIn) {
    if hidden(in.clip, in.view_pos) {
        discard;
    }
    let pixel = vec2<u32>(in.clip.xy);
    var d = key(in.clip, in.point);
    // The K nearer fragments are kept already (a slot's key only grows): the tail's, at once.
    if d < atomicLoad(&depths[slot(pixel, LAYERS - 1u)]) {
        return;
    }
    for (var k = 0u; k < LAYERS; k++) {
        let kept = atomicMax(&depths[slot(pixel, k)], d);
        if kept == 0u {
            return;
        }
        d = min(kept, d);
    }
}

struct TailOut {
    @location(0) accum: vec4<f32>,
    @location(1) reveal: f32,
}

@fragment
fn fs_colors(in: LayerOut) -> TailOut {
    if hidden(in.clip, in.view_pos) {
        discard;
    }
    // The line's G-buffer texel, composited as the composite does it: color · (1 − strength · ao)
    // + specular, its AO the object-space one at its own point.
    let g = line_gbuffer(in.view_pos, in.view_tangent, in.color);
    var ao = 0.0;
    if OCTANTS {
        ao = object_ao(g.nd.xyz, vec2<u32>(pack4x8unorm(in.octants_lo), pack4x8unorm(in.octants_hi)));
    }
    let rgb = g.color.rgb * (1.0 - clamp(layer.strength * ao, 0.0, 1.0)) + g.specular;
    let pixel = vec2<u32>(in.clip.xy);
    let d = key(in.clip, in.point);
    let tail = TailOut(vec4<f32>(rgb * in.alpha, in.alpha), in.alpha);
    // Behind the K-th (the slots are sorted, nearest first): the tail's, without a search.
    if d < atomicLoad(&depths[slot(pixel, LAYERS - 1u)]) {
        return tail;
    }
    for (var k = 0u; k < LAYERS; k++) {
        let s = slot(pixel, k);
        if atomicLoad(&depths[s]) == d {
            colors[s] = vec2<u32>(pack2x16float(rgb.rg), pack2x16float(vec2<f32>(rgb.b, in.alpha)));
            return TailOut(vec4<f32>(0.0), 0.0);
        }
    }
    return tail;
}

@vertex
fn vs_resolve(@builtin(vertex_index) vertex_index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(vertex_index);
}

@fragment
fn fs_resolve(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<u32>(position.xy) + layer.guard;
    // The pixel's kept fragments, nearest first (insertion sort on the keys: K ≤ 16).
    var keys: array<u32, MAX_LAYERS>;
    var slots: array<u32, MAX_LAYERS>;
    var n = 0u;
    for (var k = 0u; k < LAYERS; k++) {
        let s = slot(pixel, k);
        let d = atomicLoad(&depths[s]);
        if d == 0u {
            continue;
        }
        var i = n;
        while i > 0u && keys[i - 1u] < d {
            keys[i] = keys[i - 1u];
            slots[i] = slots[i - 1u];
            i -= 1u;
        }
        keys[i] = d;
        slots[i] = s;
        n += 1u;
    }
    let accum = textureLoad(tail_accum, vec2<i32>(pixel), 0);
    // No transparent fragment: the opaque picture stays as it is, not blended with nothing.
    if n == 0u && accum.a == 0.0 {
        discard;
    }
    var rgb = vec3<f32>(0.0);
    var transmittance = 1.0;
    for (var i = 0u; i < n; i++) {
        // A line counts once where its own pieces overlap: the nearest of them.
        if i > 0u && same_line(keys[i], keys[i - 1u]) {
            continue;
        }
        let c = colors[slots[i]];
        let rg = unpack2x16float(c.x);
        let ba = unpack2x16float(c.y);
        rgb += transmittance * ba.y * vec3<f32>(rg, ba.x);
        transmittance *= 1.0 - ba.y;
    }
    // The tail: its average colour, weighted by opacity, covering 1 − Π(1 − α) of what is left.
    let reveal = textureLoad(tail_reveal, vec2<i32>(pixel), 0).r;
    if accum.a > 0.0 {
        rgb += transmittance * (1.0 - reveal) * accum.rgb / accum.a;
        transmittance *= reveal;
    }
    return vec4<f32>(rgb, 1.0 - transmittance);
}
