// Culling the lines' pieces against the view and the depth pyramid (`lineao::passes::cull`),
// in two phases per frame. `early` lists the pieces visible in the last frame, which are drawn;
// then the pyramid is built from the depth they left, and every piece is tested against it:
// one whose fragments all lie behind what is drawn at each pixel they can cover, or outside
// the view, is hidden, any other is visible, and the visible ones not drawn early are drawn
// now. Each test is conservative, so the G-buffer is the one drawing every piece leaves.
// `settle` tests the drawn pieces again against the final depth, for the next frame.
//
// The tests run coarse to fine: `test_groups` tests each group of 16 clusters by its box
// (close in space: a page sorts its clusters along a Morton curve) and lists the groups that
// may be visible; `late_bounds` runs a workgroup per listed group and an invocation per piece,
// which tests the piece's bounding capsule (two points decoded, not nine) and lists the pieces
// that may be visible; `late` tests those segment by segment, an invocation each, so that
// neighbouring invocations do the same work; `settle` runs an invocation per piece drawn.
// Where the capsules cost more than the segment tests they save (a GPU: another pass, and a
// list written and read, to spare arithmetic it has plenty of), `late_direct` tests each
// piece of a listed group segment by segment at once; the marks are the same.
//
// A piece (segments 8p .. 8p + 7 of a cluster's strip) is visible where one of its segments
// is, each bounded by its two points as the vertex shader computes them: its quads' corners are
// the points pushed half a line width sideways on screen at the points' depth, so its fragments
// lie within half a line width of the two points' box on screen and no nearer than the nearer
// point (depth interpolates linearly on screen). A segment spans a few pixels: its box is
// tight, and the pyramid is read at a fine level (mostly the pixels themselves). A box in
// front of the eye projects within its corners' projections, no nearer than its nearest corner.
//
// With `LOD` each visible piece is drawn at the coarsest level of detail that leaves it within
// LOD_PIXELS of its full strip (or tube) on screen (`piece_level`): every 2nd, 4th or 8th point
// of it kept, and its ends. The coarse pieces are listed from the back of their phase's list
// and drawn with fewer vertices a piece (`lines.wgsl`'s `vs_piece_coarse`, `tubes.wgsl`'s
// `vs_tube_piece_coarse`).
//
// With `TUBES` the pieces are drawn as tubes (`tubes.wgsl`): a segment is bounded by its
// billboard (`shared/billboard.wgsl`) for the largest radius of the page's points, and a group
// by its box grown by that radius; the billboard's depth is clamped into the depth range, so
// tubes are not clipped by the near and far planes.
#import shared/billboard.wgsl
#import shared/clusters.wgsl
#import shared/geometry.wgsl

// Whether the pieces are drawn as tubes (`lineao::passes::cull::Shape`).
override TUBES: bool = false;
// Whether the pieces are drawn at a level of detail (`lineao::passes::cull::LineCull::new`'s `lod`).
override LOD: bool = false;
// A page's first culled frame knows nothing visible: `early` then also lists every piece of
// every SEED-th cluster (0: none), spread over the page by the clusters' Morton order, whose
// depth the late test culls against (`lineao::passes::cull::SEED_STRIDE`).
override SEED: u32 = 0u;

// Keep in sync with `lineao::passes::depth_pyramid::PyramidUniform`.
struct Pyramid {
    size: vec2<u32>,
    levels: u32,
    _pad: u32,
    // Per level: first texel, width, height.
    level: array<vec4<u32>, 16>,
}

@group(2) @binding(0) var<uniform> pyramid: Pyramid;
@group(2) @binding(1) var<storage, read> pyramid_texels: array<f32>;

// A page's state, in one buffer (a stage may bind 8 storage buffers, the WebGPU default):
// words 4d .. 4d + 3 the indirect arguments of draw d (`draw_of`: 0 early, 1 late, 2 and 3
// their coarse pieces), 16 the groups listed for `late`, 17 + d the pieces listed for draw d
// (these HEADER words zeroed before each frame); then per cluster a word (from `VISIBLE`):
// bit p set where piece p passed the last test, bits LEVEL_SHIFT + 2p .. + 1 the level it was
// drawn at (points kept: every 2^level-th), bit OUTSIDE_SHIFT + p set where the test that hid it
// found it outside the view (its group's box, or each of its segments: not the pyramid); then
// the listed groups.
@group(3) @binding(0) var<storage, read_write> state: array<atomic<u32>>;
// The pieces to draw (`piece_entry`): the early phase's list in the first half, the late one's
// in the second (each draw binds its half); in each, the full pieces from the front and the
// coarse ones from the back (room for both padded to whole instances: `pad`).
@group(3) @binding(1) var<storage, read_write> pieces: array<u32>;
// The indirect dispatch of `late` (x, y, 1) and, in word 3, the groups listed for it, as
// `test_groups` counts them; or `settle`'s (only bound there and in `size_dispatch` and
// `size_settle`: a dispatch cannot read its arguments from a buffer it binds). Zeroed before
// each listing.
@group(3) @binding(2) var<storage, read_write> listing: array<atomic<u32>>;
// The pieces `late_bounds` lists for `late` (cluster << 2 | piece: 3 words a cluster), then each
// piece's bounding radius (`piece_radii`: 2 words a cluster, 16 bits a piece). Bound where
// `listing` is not (`late` is dispatched from `listing`).
@group(3) @binding(3) var<storage, read_write> bounds: array<u32>;

const HEADER: u32 = 32u;
const VISIBLE: u32 = HEADER;
const LISTED_GROUPS: u32 = 16u;
const LISTED_PIECES: u32 = 17u;
// The pieces `late_bounds` listed for `late`.
const LISTED_CANDIDATES: u32 = 21u;
// A piece radius that bounds nothing (`piece_radii`).
const NO_RADIUS: u32 = 0xffffu;
const LEVEL_SHIFT: u32 = 3u;
const OUTSIDE_SHIFT: u32 = 9u;
// Why a piece was left out, as a listed piece says it (`list_all`; `shared/pieces.wgsl`).
const LEFT_OUTSIDE: u32 = 1u;
const LEFT_BEHIND: u32 = 2u;
// A test's verdict where what it tested may be visible (else LEFT_OUTSIDE or LEFT_BEHIND).
const VISIBLE_HERE: u32 = 0u;
const OUTSIDE_ALL: u32 = 7u << OUTSIDE_SHIFT;
// How far a piece drawn at a coarser level may lie from its full strip on screen (pixels).
const LOD_PIXELS: f32 = 0.5;
// The coarsest level: every 8th point kept (a piece's ends).
const LEVELS: u32 = 4u;
// Texels across at most where a group's box reads the pyramid, and a segment's (read finer, a
// box passes less often: at 10 M points 71 % of the groups of 16 for 91 % at 2, for up to 256
// reads a group; a segment's box, a few pixels and the line's width, read at 8 rather than 2
// texels across — mostly the pixels themselves, not the farthest of 8 × 8 around them — leaves
// 54 % fewer pieces to draw at 50 M points, 1.69 % of them, for 17 % more time culling).
const GROUP_SPAN: u32 = 16u;
const SEGMENT_SPAN: u32 = 8u;

fn cluster_count() -> u32 {
    return arrayLength(&clusters);
}

// Where the late list starts in `pieces`.
fn late_list() -> u32 {
    return arrayLength(&pieces) / 2u;
}

// Where listed group slot `slot` lies in `state`.
fn seen_at(slot: u32) -> u32 {
    return VISIBLE + cluster_count() + slot;
}

// Vertices of an instance of draw `d`'s culled lines (`lines.wgsl`'s `vs_piece`: each piece's
// strip, `vs_piece_coarse` at most every second point's) or tubes (`tubes.wgsl`'s
// `vs_tube_piece`: six vertices a segment, at most every second point's for `vs_tube_piece_coarse`).
fn instance_vertices(d: u32) -> u32 {
    if TUBES {
        return PIECES_PER_INSTANCE * 6u * select(PIECE_SEGMENTS, PIECE_SEGMENTS / 2u, d >= 2u);
    }
    return PIECES_PER_INSTANCE * select(PIECE_STRIDE, COARSE_PIECE_STRIDE, d >= 2u);
}

// The draw of a piece of phase `phase` (0 early, 1 late) drawn at `level`.
fn draw_of(phase: u32, level: u32) -> u32 {
    return phase + select(0u, 2u, level > 0u);
}

// A listed piece: its cluster, why it was left out (0: it was not), its level, which piece.
fn piece_entry(cluster: u32, left: u32, level: u32, p: u32) -> u32 {
    return (cluster << 6u) | (left << 4u) | (level << 2u) | p;
}

// Where slot `slot` of draw `d`'s list lies in `pieces`.
fn list_index(d: u32, slot: u32) -> u32 {
    let start = (d & 1u) * late_list();
    return select(start + slot, start + late_list() - 1u - slot, d >= 2u);
}
// Workgroups per row of a direct dispatch (`lineao::passes::cull`'s ROW), 64 invocations each.
const ROW: u32 = 32768u;
// Workgroups per row of an indirect one.
const DISPATCH_ROW: u32 = 65535u;
// What the rasterizer's interpolation and the two computations of a point's depth may differ
// by (about 16 steps of f32 near 1).
const DEPTH_MARGIN: f32 = 2e-6;

fn invocation(group: vec3<u32>, local: u32) -> u32 {
    return (group.x + group.y * ROW) * 64u + local;
}

// Lists piece `p` of cluster `cluster` at `level` for phase `phase` (0 early, 1 late): its
// slot from its draw's piece count, an instance more for every PIECES_PER_INSTANCE of them.
fn append(phase: u32, cluster: u32, level: u32, p: u32) {
    append_left(phase, cluster, 0u, level, p);
}

// `append` of a piece the cull left out for reason `left` (`list_all`).
fn append_left(phase: u32, cluster: u32, left: u32, level: u32, p: u32) {
    let d = draw_of(phase, level);
    let slot = atomicAdd(&state[LISTED_PIECES + d], 1u);
    pieces[list_index(d, slot)] = piece_entry(cluster, left, level, p);
    if slot % PIECES_PER_INSTANCE == 0u {
        atomicAdd(&state[4u * d + 1u], 1u);
    }
}

// The level piece `p` of a cluster whose mark is `bits` was drawn at.
fn marked_level(bits: u32, p: u32) -> u32 {
    return (bits >> (LEVEL_SHIFT + 2u * p)) & 3u;
}

// The level piece `p` of a cluster whose mark is `bits` is drawn at (marks a cull at levels of
// detail left say nothing to one without).
fn drawn_level(bits: u32, p: u32) -> u32 {
    return select(0u, marked_level(bits, p), LOD);
}

// The vertices an instance of each draw has, once a frame (invocation `i` < 4).
fn start_draw(i: u32) {
    if i < 4u {
        atomicStore(&state[4u * i], instance_vertices(i));
    }
}

@compute @workgroup_size(64)
fn early(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = invocation(group, local);
    start_draw(i);
    if i >= cluster_count() {
        return;
    }
    var bits = atomicLoad(&state[VISIBLE + i]);
    if SEED > 0u && i % max(SEED, 1u) == 0u && is_selected(clusters[i]) {
        // Whole, unmarked: the late test marks (and draws again) those that are visible.
        let segments = drawn_points(clusters[i]) - 1u;
        bits = select(1u, select(3u, 7u, segments > 2u * PIECE_SEGMENTS), segments > PIECE_SEGMENTS);
    }
    for (var p = 0u; p < 3u; p++) {
        if (bits & (1u << p)) != 0u {
            append(0u, i, drawn_level(bits, p), p);
        }
    }
}

// The frozen cull's picture of what it left out (`lineao::passes::cull::Frozen::All`): every
// piece of the selected clusters listed for the early draw, whole (the camera has moved), the
// ones not marked with why the last test left them out (outside the view, or behind the
// pyramid).
@compute @workgroup_size(64)
fn list_all(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = invocation(group, local);
    start_draw(i);
    if i >= cluster_count() || !is_selected(clusters[i]) {
        return;
    }
    let bits = atomicLoad(&state[VISIBLE + i]);
    let segments = drawn_points(clusters[i]) - 1u;
    for (var p = 0u; p * PIECE_SEGMENTS < segments; p++) {
        if (bits & (1u << p)) != 0u {
            append(0u, i, 0u, p);
        } else {
            let outside = (bits & (1u << (OUTSIDE_SHIFT + p))) != 0u;
            append_left(0u, i, select(LEFT_BEHIND, LEFT_OUTSIDE, outside), 0u, p);
        }
    }
}

// After a listing: the slots of each draw's last instance past its pieces hold NO_PIECE, so
// they draw nothing (`shared/pieces.wgsl`).
@compute @workgroup_size(32)
fn pad(@builtin(local_invocation_index) local: u32) {
    let d = local / 8u;
    let count = atomicLoad(&state[LISTED_PIECES + d]);
    let slot = count + local % 8u;
    if slot % PIECES_PER_INSTANCE != 0u && slot < late_list() {
        pieces[list_index(d, slot)] = NO_PIECE;
    }
}

// Lists the groups whose box may be visible; unmarks the pieces of the others.
@compute @workgroup_size(64)
fn test_groups(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let g = invocation(group, local);
    let clusters_of_page = cluster_count();
    if g * GROUP_CLUSTERS >= clusters_of_page {
        return;
    }
    let box = cluster_groups[g];
    // Tubes reach their radius beyond their points.
    let grow = vec3<f32>(select(0.0, radius_bound(), TUBES));
    let verdict = world_box_verdict(box.lo.xyz - grow, box.hi.xyz + grow);
    if verdict == VISIBLE_HERE {
        atomicStore(&state[seen_at(atomicAdd(&listing[3], 1u))], g);
        return;
    }
    let mark = select(0u, OUTSIDE_ALL, verdict == LEFT_OUTSIDE);
    for (var i = g * GROUP_CLUSTERS; i < min((g + 1u) * GROUP_CLUSTERS, clusters_of_page); i++) {
        atomicStore(&state[VISIBLE + i], mark);
    }
}

// The indirect dispatch of the listed groups, a workgroup each (rows of 65 535).
@compute @workgroup_size(1)
fn size_dispatch() {
    let listed = atomicLoad(&listing[3]);
    atomicStore(&listing[0], min(listed, DISPATCH_ROW));
    atomicStore(&listing[1], (listed + DISPATCH_ROW - 1u) / DISPATCH_ROW);
    atomicStore(&listing[2], 1u);
    atomicStore(&state[LISTED_GROUPS], listed);
}

// The indirect dispatch of an invocation each for `count` items (rows of 65 535 workgroups of
// 64).
fn size_over(count: u32) {
    let groups = (count + 63u) / 64u;
    atomicStore(&listing[0], min(groups, DISPATCH_ROW));
    atomicStore(&listing[1], (groups + DISPATCH_ROW - 1u) / DISPATCH_ROW);
    atomicStore(&listing[2], 1u);
}

// The piece of invocation `local` of workgroup `group` (a listed group's slot): (cluster,
// piece, first, last) with last < first where there is none.
fn listed_piece(group: vec3<u32>, local: u32) -> vec4<u32> {
    let slot = group.x + group.y * DISPATCH_ROW;
    let none = vec4<u32>(0u, 0u, 1u, 0u);
    if slot >= atomicLoad(&state[LISTED_GROUPS]) {
        return none;
    }
    let i = atomicLoad(&state[seen_at(slot)]) * GROUP_CLUSTERS + local / 3u;
    if i >= cluster_count() {
        return none;
    }
    let p = local % 3u;
    let drawn = drawn_points(clusters[i]);
    let first = p * PIECE_SEGMENTS;
    return vec4<u32>(i, p, first, min(first + PIECE_SEGMENTS, drawn - 1u));
}

// Whether cluster `i`'s piece of mark `bit` is marked visible.
fn marked(i: u32, bit: u32) -> bool {
    return (atomicLoad(&state[VISIBLE + i]) & bit) != 0u;
}

// Marks piece `p` of cluster `i` visible or not as `verdict` says (and why not), and lists a
// visible one the early draw did not draw (in full: its level is found by `settle`). Only a
// mark that changes is written.
fn mark(i: u32, p: u32, verdict: u32) {
    let bit = 1u << p;
    let outside_bit = 1u << (OUTSIDE_SHIFT + p);
    let bits = atomicLoad(&state[VISIBLE + i]);
    let before = (bits & bit) != 0u;
    if verdict == VISIBLE_HERE {
        if (bits & outside_bit) != 0u {
            atomicAnd(&state[VISIBLE + i], ~outside_bit);
        }
        if !before {
            atomicOr(&state[VISIBLE + i], bit);
            append(1u, i, 0u, p);
        }
        return;
    }
    let outside = select(0u, outside_bit, verdict == LEFT_OUTSIDE);
    if before || (bits & outside_bit) != outside {
        atomicAnd(&state[VISIBLE + i], ~(bit | level_bits(p) | outside_bit));
        atomicOr(&state[VISIBLE + i], outside);
    }
}

// An invocation per piece of a listed group: a piece whose bounding capsule is hidden is marked
// so; the others are listed for `late`.
@compute @workgroup_size(48)
fn late_bounds(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let piece = listed_piece(group, local);
    if piece.w <= piece.z {
        return;
    }
    let verdict = capsule_verdict(piece.x, piece.y, piece.z, piece.w);
    if verdict != VISIBLE_HERE {
        mark(piece.x, piece.y, verdict);
        return;
    }
    bounds[atomicAdd(&state[LISTED_CANDIDATES], 1u)] = (piece.x << 2u) | piece.y;
}

// The indirect dispatch of `late`: an invocation per piece `late_bounds` listed.
@compute @workgroup_size(1)
fn size_late() {
    size_over(atomicLoad(&state[LISTED_CANDIDATES]));
}

// An invocation per piece `late_bounds` listed: tested segment by segment and marked.
@compute @workgroup_size(64)
fn late(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let slot = (group.x + group.y * DISPATCH_ROW) * 64u + local;
    if slot >= atomicLoad(&state[LISTED_CANDIDATES]) {
        return;
    }
    let entry = bounds[slot];
    let i = entry >> 2u;
    let p = entry & 3u;
    let c = clusters[i];
    let first = p * PIECE_SEGMENTS;
    mark(i, p, piece_verdict(c, first, min(first + PIECE_SEGMENTS, drawn_points(c) - 1u)));
}

// An invocation per piece of a listed group, tested segment by segment without its capsule
// first (`lineao::passes::cull::LineCull::set_capsules`) and marked.
@compute @workgroup_size(48)
fn late_direct(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let piece = listed_piece(group, local);
    if piece.w > piece.z {
        mark(piece.x, piece.y, piece_verdict(clusters[piece.x], piece.z, piece.w));
    }
}

// Where piece radii start in `bounds`.
fn radii_at() -> u32 {
    return 3u * cluster_count();
}

// Once a page (its cull state made): each piece's bounding radius around the segment between
// its ends (a capsule), all its points as decoded, in units of two of its cluster's grid steps
// rounded up, at least one (NO_RADIUS where that does not fit, or a piece the cluster lacks).
@compute @workgroup_size(64)
fn piece_radii(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = invocation(group, local);
    if i >= cluster_count() {
        return;
    }
    let c = clusters[i];
    let drawn = drawn_points(c);
    var radii = array<u32, 3>(NO_RADIUS, NO_RADIUS, NO_RADIUS);
    for (var p = 0u; p < 3u && p * PIECE_SEGMENTS + 1u < drawn; p++) {
        let first = p * PIECE_SEGMENTS;
        let last = min(first + PIECE_SEGMENTS, drawn - 1u);
        let a = strip_point(c, first);
        let ab = strip_point(c, last) - a;
        var r = 0.0;
        for (var k = first + 1u; k < last; k++) {
            let q = strip_point(c, k) - a;
            let t = clamp(dot(q, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
            r = max(r, length(q - t * ab));
        }
        // A step more for rounding (a grid of zero steps holds one point); at least one, for
        // 0 says the radius is not found yet.
        let units = select(1.0, ceil(r / (2.0 * c.scale)) + 1.0, c.scale > 0.0);
        if units < f32(NO_RADIUS) {
            radii[p] = u32(units);
        }
    }
    bounds[radii_at() + 2u * i] = radii[0] | (radii[1] << 16u);
    bounds[radii_at() + 2u * i + 1u] = radii[2] | (NO_RADIUS << 16u);
}

// Strip point `k` of cluster `c` as decoded (past its own, the next cluster's first).
fn strip_point(c: Cluster, k: u32) -> vec3<f32> {
    var owner = c;
    if k >= (c.flags & CLUSTER_COUNT) {
        owner = clusters[c.next];
    }
    return decode_point(c.first + k, owner);
}

// The verdict on piece `p` (strip points `first ..= last`) of cluster `i` by its bounding capsule
// (for tubes grown by the radius bound): the boxes in view space around its ends (the view is
// rigid) hull it, and project within their corners' projections, no nearer than their nearest
// corner; they hold every fragment the piece's segments can leave, so a capsule hidden (or
// outside) hides the piece: `piece_verdict` never finds visible a piece this finds hidden.
fn capsule_verdict(i: u32, p: u32, first: u32, last: u32) -> u32 {
    let c = clusters[i];
    if !is_selected(c) {
        return LEFT_BEHIND;
    }
    let units = (bounds[radii_at() + 2u * i + (p >> 1u)] >> ((p & 1u) * 16u)) & 0xffffu;
    // No bound, or none found yet (the buffer starts zeroed).
    if units == NO_RADIUS || units == 0u {
        return VISIBLE_HERE;
    }
    var r = 2.0 * f32(units) * c.scale;
    if TUBES {
        r += radius_bound();
    }
    let ends = array<vec4<f32>, 2>(
        frame.proj * (frame.view * vec4<f32>(strip_point(c, first), 1.0)),
        frame.proj * (frame.view * vec4<f32>(strip_point(c, last), 1.0)),
    );
    // The view-space axes r long, in clip space.
    let axes = array<vec4<f32>, 3>(frame.proj[0] * r, frame.proj[1] * r, frame.proj[2] * r);
    var rect = NdcBounds(vec3<f32>(3.0e38), vec3<f32>(-3.0e38));
    for (var k = 0u; k < 16u; k++) {
        let signs = vec3<f32>(f32(k & 1u), f32((k >> 1u) & 1u), f32((k >> 2u) & 1u)) * 2.0 - 1.0;
        let offset = signs.x * axes[0] + signs.y * axes[1] + signs.z * axes[2];
        if !widen(&rect, ends[k >> 3u] + offset) {
            // Reaches behind the eye: no bound on screen.
            return VISIBLE_HERE;
        }
    }
    // Read as a segment's box is: its rectangle holds theirs, so it is read at their level or
    // a coarser one, never finer, and hides no piece their test would show (the marks stay
    // theirs).
    return box_verdict(rect.lo, rect.hi, SEGMENT_SPAN);
}

// The bits of a cluster's mark that hold piece `p`'s level.
fn level_bits(p: u32) -> u32 {
    return 3u << (LEVEL_SHIFT + 2u * p);
}

// The indirect dispatch of `settle`: an invocation per piece drawn, early and late (rows of
// 65 535 workgroups of 64).
@compute @workgroup_size(1)
fn size_settle() {
    var drawn = 0u;
    for (var d = 0u; d < 4u; d++) {
        drawn += atomicLoad(&state[LISTED_PIECES + d]);
    }
    size_over(drawn);
}

// After the late draw, against the pyramid of the frame's final depth (and after
// `test_groups`, which unmarks the pieces of hidden groups): the pieces drawn (the only ones
// marked: the early list holds the marked ones, the late one those marked since) that the
// frame's lines hide after all are unmarked, so the next frame's early phase draws only what
// this one shows (after a first frame or a cut, the late phase marks all that passed against
// the early phase's depth); with `LOD`, at the level found here.
@compute @workgroup_size(64)
fn settle(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    var i = (group.x + group.y * DISPATCH_ROW) * 64u + local;
    // Slot i of the four lists one after the other.
    var d = 0u;
    for (; d < 4u; d++) {
        let count = atomicLoad(&state[LISTED_PIECES + d]);
        if i < count {
            break;
        }
        i -= count;
    }
    if d == 4u {
        return;
    }
    let entry = pieces[list_index(d, i)];
    let cluster = entry >> 6u;
    let p = entry & 3u;
    let bit = 1u << p;
    if !marked(cluster, bit) {
        return;
    }
    let c = clusters[cluster];
    let first = p * PIECE_SEGMENTS;
    let last = min(first + PIECE_SEGMENTS, drawn_points(c) - 1u);
    // Drawn, so in the view: hidden now behind the final depth.
    if piece_verdict(c, first, last) != VISIBLE_HERE {
        atomicAnd(&state[VISIBLE + cluster], ~(bit | level_bits(p)));
    } else if LOD {
        // The level the next frame draws it at (here, where only the pieces drawn are tested:
        // in `late`, the invocations beside a visible piece would wait for it).
        let level = piece_level(c, first, last);
        atomicAnd(&state[VISIBLE + cluster], ~level_bits(p));
        atomicOr(&state[VISIBLE + cluster], level << (LEVEL_SHIFT + 2u * p));
    }
}

// The coarsest level (< LEVELS) at which strip points `first ..= last` of cluster `c` lie within
// LOD_PIXELS of their full strip on screen: where every 2^level-th point and the last are kept,
// each dropped point lies within LOD_PIXELS of the segment between the kept ones around it
// (its distance in view space, at the scale of the piece's nearest point), and the sideways
// push at it turns by no more (half a line width times its tangent's distance from the
// segment's direction). A kept point keeps its own tangent, so the strip's corners there, and
// the joins to the next pieces, are the full strip's. Tubes: the solid around the kept points
// lies within the same distance of the full one (each is its axis grown by the radius), and
// its rim turns by the radius (the page's largest) times that distance of directions, on screen.
fn piece_level(c: Cluster, first: u32, last: u32) -> u32 {
    var p: array<vec3<f32>, 9>;
    let n = last - first + 1u;
    var nearest = 3.0e38;
    for (var k = 0u; k < n; k++) {
        let view_pos = frame.view * vec4<f32>(strip_point(c, first + k), 1.0);
        let w = (frame.proj * view_pos).w;
        if w <= 0.0 {
            return 0u;
        }
        nearest = min(nearest, w);
        p[k] = view_pos.xyz;
    }
    // Pixels a view-space unit spans at the nearest point.
    let px = 0.5 * max(frame.proj[0][0] * frame.viewport.x, frame.proj[1][1] * frame.viewport.y) / nearest;
    let half_width = select(0.5 * frame.line_width_px, radius_bound() * px, TUBES);
    for (var level = LEVELS - 1u; level > 0u; level--) {
        let stride = 1u << level;
        var fits = true;
        for (var k = 1u; k + 1u < n && fits; k++) {
            if k % stride == 0u {
                continue;
            }
            let a = p[k - k % stride];
            let b = p[min(k - k % stride + stride, n - 1u)];
            let ab = b - a;
            let t = clamp(dot(p[k] - a, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
            let off_line = length(p[k] - (a + t * ab)) * px;
            let turn = length(normalize(p[k + 1u] - p[k - 1u]) - normalize(ab)) * half_width;
            fits = off_line + turn <= LOD_PIXELS;
        }
        if fits {
            return level;
        }
    }
    return 0u;
}

// Whether strip points `first ..= last` of cluster `c` may leave a fragment in front of the
// pyramid: whether one of their segments may (never for a cluster selected out). Hidden,
// LEFT_OUTSIDE where each segment lies outside the view, else LEFT_BEHIND.
fn piece_verdict(c: Cluster, first: u32, last: u32) -> u32 {
    if !is_selected(c) {
        return LEFT_BEHIND;
    }
    var previous = vec3<f32>(0.0);
    var verdict = LEFT_OUTSIDE;
    for (var k = first; k <= last; k++) {
        // As the vertex shader computes it.
        let view_pos = frame.view * vec4<f32>(strip_point(c, k), 1.0);
        var segment = LEFT_OUTSIDE;
        if TUBES {
            if k > first {
                segment = tube_verdict(previous, view_pos.xyz);
            }
            previous = view_pos.xyz;
        } else {
            let clip = frame.proj * view_pos;
            if clip.w <= 0.0 {
                // Behind the eye: the rasterizer clips the piece, and its box says nothing.
                return VISIBLE_HERE;
            }
            let ndc = clip.xyz / clip.w;
            if k > first {
                segment = segment_verdict(previous, ndc);
            }
            previous = ndc;
        }
        if segment == VISIBLE_HERE {
            return VISIBLE_HERE;
        }
        // Behind once one segment is in the view.
        verdict = max(verdict, segment);
    }
    return verdict;
}

// The largest tube radius of the page's points (world units): the frame's, or the largest a
// point holds.
fn radius_bound() -> f32 {
    return max(frame.tube_radius, cluster_page.max_radius);
}

// The verdict on the tube segment between view positions `a` and `b` (VISIBLE_HERE where it
// may leave a fragment in front of the pyramid): within its billboard (for the radius bound: no
// smaller on screen and no farther), whose corners lie at most √2 × its larger reach from an end
// in x and in y, and no nearer than the billboard's depth (the fragment shader's promise). An end
// behind the eye leaves no billboard: drawn, for the bound says nothing.
fn tube_verdict(a: vec3<f32>, b: vec3<f32>) -> u32 {
    if behind_eye(a) || behind_eye(b) {
        return VISIBLE_HERE;
    }
    let r = radius_bound();
    let bb = billboard(a, b, r, r);
    let reach = 1.4143 * max(bb.reach_a, bb.reach_b) + 1.0;
    return pixels_verdict(min(bb.pa, bb.pb) - reach, max(bb.pa, bb.pb) + reach, bb.depth, SEGMENT_SPAN);
}

// The verdict on what lies in the world box `lo`..`hi`.
fn world_box_verdict(lo: vec3<f32>, hi: vec3<f32>) -> u32 {
    var rect = NdcBounds(vec3<f32>(3.0e38), vec3<f32>(-3.0e38));
    for (var k = 0u; k < 8u; k++) {
        let corner = select(lo, hi, vec3<bool>((k & 1u) != 0u, (k & 2u) != 0u, (k & 4u) != 0u));
        if !widen(&rect, frame.proj * (frame.view * vec4<f32>(corner, 1.0))) {
            // Reaches behind the eye: no bound on screen.
            return VISIBLE_HERE;
        }
    }
    return box_verdict(rect.lo, rect.hi, GROUP_SPAN);
}

// A box in NDC.
struct NdcBounds {
    lo: vec3<f32>,
    hi: vec3<f32>,
}

// Widens `bounds` to hold clip position `clip`; false where it lies behind the eye.
fn widen(bounds: ptr<function, NdcBounds>, clip: vec4<f32>) -> bool {
    if clip.w <= 0.0 {
        return false;
    }
    let ndc = clip.xyz / clip.w;
    (*bounds).lo = min((*bounds).lo, ndc);
    (*bounds).hi = max((*bounds).hi, ndc);
    return true;
}

// The verdict on the segment between points at NDC `a` and `b`. Its two triangles' corners lie
// half a line width from `a` or `b` on screen, at their depths.
fn segment_verdict(a: vec3<f32>, b: vec3<f32>) -> u32 {
    return box_verdict(min(a, b), max(a, b), SEGMENT_SPAN);
}

// The verdict on what lies in the NDC box `lo`..`hi` (drawn half a line width wider).
fn box_verdict(lo: vec3<f32>, hi: vec3<f32>, span: u32) -> u32 {
    // Wholly in front of the near plane or beyond the far one: clipped (lines; a tube's
    // depth is clamped into the range).
    if !TUBES && (hi.z < 0.0 || lo.z > 1.0) {
        return LEFT_OUTSIDE;
    }
    // The pixels whose centres its quads can cover (a pixel more for rounding).
    let size = vec2<f32>(pyramid.size);
    let reach = 0.5 * frame.line_width_px + 1.0;
    let top_left = vec2<f32>(lo.x * 0.5 + 0.5, 0.5 - hi.y * 0.5) * size - reach;
    let bottom_right = vec2<f32>(hi.x * 0.5 + 0.5, 0.5 - lo.y * 0.5) * size + reach;
    return pixels_verdict(top_left, bottom_right, clamp(lo.z, 0.0, 1.0), span);
}

// The verdict on a fragment no nearer than depth `nearest` on a pixel whose centre lies between
// `top_left` and `bottom_right`: LEFT_OUTSIDE where no such pixel is in the targets,
// LEFT_BEHIND where it lies behind the pyramid at each, else VISIBLE_HERE.
fn pixels_verdict(top_left: vec2<f32>, bottom_right: vec2<f32>, nearest: f32, span: u32) -> u32 {
    let size = vec2<f32>(pyramid.size);
    if any(bottom_right < vec2<f32>(0.0)) || any(top_left >= size) {
        return LEFT_OUTSIDE;
    }
    let a_px = vec2<u32>(clamp(floor(top_left), vec2<f32>(0.0), size - 1.0));
    let b_px = vec2<u32>(clamp(floor(bottom_right), vec2<f32>(0.0), size - 1.0));
    // The finest level where the rectangle spans at most span × span texels.
    var l = 0u;
    while l + 1u < pyramid.levels && any((b_px >> vec2<u32>(l)) - (a_px >> vec2<u32>(l)) >= vec2<u32>(span)) {
        l++;
    }
    let level = pyramid.level[l];
    let ta = a_px >> vec2<u32>(l);
    let tb = b_px >> vec2<u32>(l);
    var farthest = 0.0;
    for (var y = ta.y; y <= tb.y; y++) {
        for (var x = ta.x; x <= tb.x; x++) {
            farthest = max(farthest, pyramid_texels[level.x + y * level.y + x]);
        }
    }
    return select(LEFT_BEHIND, VISIBLE_HERE, nearest <= farthest + DEPTH_MARGIN);
}
