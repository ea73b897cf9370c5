// Polylines as clusters, pulled by the vertex shader (`lineao::line_geometry`, whose clusters
// module lays them out): every point once, 16 bits per axis on its cluster's own grid; a
// cluster's strip also draws the next cluster's first point, decoded with that cluster's grid,
// so joins between clusters are exact. Bind group 1 is one page of clusters.

// Keep in sync with `lineao::line_geometry::ClusterRecord`.
struct Cluster {
    origin: vec3<f32>,
    scale: f32,
    first: u32,
    // Bits 0–4: point count; 5: the run goes on before it; 6: after it; 8–31: which inner
    // points are bent (take both sides in the alternating strip), inner point k at bit 7 + k.
    flags: u32,
    previous: u32,
    next: u32,
}

// Keep in sync with `lineao::line_geometry::PageUniform`.
struct ClusterPage {
    // Which attribute arrays hold data: 1 octants, 2 scalars, 4 radii.
    attributes: u32,
    // The largest tube radius its points hold (0 where none: the frame's), for the cull.
    max_radius: f32,
    _pad1: u32,
    _pad2: u32,
}

const CLUSTER_COUNT: u32 = 0x1fu;
const JOINS_PREVIOUS: u32 = 0x20u;
const JOINS_NEXT: u32 = 0x40u;
const DESELECTED: u32 = 0x80u;
const BENT_SHIFT: u32 = 8u;
const HAS_OCTANTS: u32 = 1u;
const HAS_SCALARS: u32 = 2u;
const HAS_RADII: u32 = 4u;
// The culled lines' unit (`lineao::passes::cull`): a piece of a cluster's strip, segments
// 8p .. 8p + 7 of it (points 8p ..= 8p + 8), so a cluster has at most three.
const PIECE_SEGMENTS: u32 = 8u;
// The culled lines' draws take PIECES_PER_INSTANCE pieces an instance, each its full strip (its
// points twice) and two vertices that join it to the next by zero-area triangles: many
// instances of a few vertices each are slow on some GPUs (a whole brain's pieces on an H200).
const PIECES_PER_INSTANCE: u32 = 8u;
const PIECE_STRIDE: u32 = 2u * (PIECE_SEGMENTS + 1u) + 2u;
// A coarse piece's (`lineao::passes::cull`'s level of detail): at most every second point.
const COARSE_PIECE_STRIDE: u32 = 2u * (PIECE_SEGMENTS / 2u + 1u) + 2u;
// A list slot that holds no piece.
const NO_PIECE: u32 = 0xffffffffu;
// Clusters of a group (`lineao::line_geometry::GROUP_CLUSTERS`).
const GROUP_CLUSTERS: u32 = 16u;

// x | y << 16 per point; z two points to a word.
@group(1) @binding(0) var<storage, read> cluster_xy: array<u32>;
@group(1) @binding(1) var<storage, read> cluster_z: array<u32>;
@group(1) @binding(2) var<storage, read> clusters: array<Cluster>;
// Per point, where the page has them: eight octant visibilities as unorm8, the colormap's
// scalar, the tube radius as f16 (two to a word; 0 = the frame's).
@group(1) @binding(3) var<storage, read> cluster_octants: array<vec2<u32>>;
@group(1) @binding(4) var<storage, read> cluster_scalars: array<f32>;
@group(1) @binding(5) var<storage, read> cluster_radii: array<u32>;
@group(1) @binding(6) var<uniform> cluster_page: ClusterPage;
// Per group of GROUP_CLUSTERS consecutive clusters (close in space), the box of every point
// their strips draw, as decoded (the cull's first test).
struct ClusterGroup {
    lo: vec4<f32>,
    hi: vec4<f32>,
}
@group(1) @binding(7) var<storage, read> cluster_groups: array<ClusterGroup>;

// Point `i` of the page on the grid of cluster `c` (its own, or for the next cluster's first
// point, the next's).
fn decode_point(i: u32, c: Cluster) -> vec3<f32> {
    return decode_on_grid(i, c.origin, c.scale);
}

// Point `i` of the page on the grid of `origin` and `scale`.
fn decode_on_grid(i: u32, origin: vec3<f32>, scale: f32) -> vec3<f32> {
    let xy = cluster_xy[i];
    let z = (cluster_z[i >> 1u] >> ((i & 1u) << 4u)) & 0xffffu;
    let q = vec3<f32>(f32(xy & 0xffffu), f32(xy >> 16u), f32(z));
    return fma(q, vec3<f32>(scale), origin);
}

// A point of a cluster's strip: where it is, its unit vertex tangent (the central difference
// of its neighbours, else a one-sided one, else +x), and its index in the page.
struct PulledPoint {
    position: vec3<f32>,
    tangent: vec3<f32>,
    index: u32,
}

// The points a cluster's strip draws: its own, and the next cluster's first when its run goes on.
// Whether the cluster's streamline is selected (`LineGeometry::set_selection`): a cluster
// selected out is neither drawn nor culled visible.
fn is_selected(c: Cluster) -> bool {
    return (c.flags & DESELECTED) == 0u;
}

fn drawn_points(c: Cluster) -> u32 {
    return (c.flags & CLUSTER_COUNT) + select(0u, 1u, (c.flags & JOINS_NEXT) != 0u);
}

// Point `k` (< drawn_points) of cluster `c` with its vertex tangent. Its neighbours across a
// cluster border are decoded on their clusters' grids (the next cluster's first point, k =
// count, on the next one's). Each of the three points is decoded once, its grid chosen by
// `select`: a CPU rasterizer runs both sides of every branch for every lane, and the branches
// this had (a point inside the cluster or at its end) decoded six (with OCTANTS of `tubes.wgsl`,
// the tubes' vertices alone took 0.71× the time after, lavapipe, 1 M vertices).
fn pulled_point(c: Cluster, k: u32) -> PulledPoint {
    let count = c.flags & CLUSTER_COUNT;
    let i = c.first + k;
    let joins_previous = (c.flags & JOINS_PREVIOUS) != 0u;
    let joins_next = (c.flags & JOINS_NEXT) != 0u;
    let before = clusters[select(0u, c.previous, joins_previous)];
    let after = clusters[select(0u, c.next, joins_next)];
    let own = k < count;
    let p = decode_on_grid(i, select(after.origin, c.origin, own), select(after.scale, c.scale, own));
    // The previous point: the cluster's, else the previous cluster's last, else none.
    let has_previous = k > 0u || joins_previous;
    let previous = decode_on_grid(
        select(i, i - 1u, has_previous),
        select(before.origin, c.origin, k > 0u),
        select(before.scale, c.scale, k > 0u),
    );
    // The next point: the cluster's, else the next cluster's first or second, else none.
    let has_next = k + 1u < count || joins_next;
    let next_own = k + 1u < count;
    let next = decode_on_grid(
        select(i, i + 1u, has_next),
        select(after.origin, c.origin, next_own),
        select(after.scale, c.scale, next_own),
    );
    return PulledPoint(p, vertex_tangent(select(p, previous, has_previous), p, select(p, next, has_next)), i);
}

// The unit vertex tangent at `p` between `previous` and `next` (which repeat `p` at a run's
// ends): the central difference, else a one-sided one, else +x.
fn vertex_tangent(previous: vec3<f32>, p: vec3<f32>, next: vec3<f32>) -> vec3<f32> {
    var t = next - previous;
    if dot(t, t) == 0.0 {
        t = next - p;
    }
    if dot(t, t) == 0.0 {
        t = p - previous;
    }
    if dot(t, t) == 0.0 {
        t = vec3<f32>(1.0, 0.0, 0.0);
    }
    return normalize(t);
}

fn point_scalar(i: u32) -> f32 {
    if (cluster_page.attributes & HAS_SCALARS) == 0u {
        return 0.0;
    }
    return cluster_scalars[i];
}

// The tube radius at point `i`; 0 where the page holds none (the frame's then).
fn point_radius(i: u32) -> f32 {
    if (cluster_page.attributes & HAS_RADII) == 0u {
        return 0.0;
    }
    return positive_f16((cluster_radii[i >> 1u] >> ((i & 1u) << 4u)) & 0xffffu);
}

// A non-negative half-precision float's bits as f32 (by hand: `unpack2x16float` needs a
// capability some backends lack).
fn positive_f16(h: u32) -> f32 {
    let exponent = (h >> 10u) & 0x1fu;
    let mantissa = h & 0x3ffu;
    if exponent == 0u {
        return f32(mantissa) * exp2(-24.0);
    }
    return bitcast<f32>(((exponent + 112u) << 23u) | (mantissa << 13u));
}

// Octants 0–3 and 4–7 of point `i`; all visible where the page holds none.
fn point_octants(i: u32) -> array<vec4<f32>, 2> {
    if (cluster_page.attributes & HAS_OCTANTS) == 0u {
        return array<vec4<f32>, 2>(vec4<f32>(1.0), vec4<f32>(1.0));
    }
    let packed = cluster_octants[i];
    return array<vec4<f32>, 2>(unpack4x8unorm(packed.x), unpack4x8unorm(packed.y));
}
