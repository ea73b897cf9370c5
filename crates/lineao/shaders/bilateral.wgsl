// Separable bilateral blur (a depth-aware Gaussian, as the VO paper uses after its samples):
// one axis per pipeline (AXIS 0 = x, 1 = y), applied x then y. Each geometry neighbour k
// pixels away weighs exp(−k²/(2σ_s²) − Δz²/(2σ_z²)), Δz its linear depth minus the centre's in
// world units; the background neither receives nor gives occlusion.
//
// Over anatomy slices (`slices_only`) only the slices' pixels (the G-buffer colour's alpha 0,
// `shaders/slices.wgsl`) receive: every other keeps its occlusion. Then `list_tiles` lists the
// SLICE_TILE² tiles that the slices' fragments marked (and, for the x half, those within the radius
// above and below them), `dispatch_args` turns the counts into indirect dispatches, and
// `bilateral_tiles` runs a workgroup per listed tile.
#import shared/nd.wgsl
#import shared/view.wgsl
// SLICE_TILE: `lineao::targets::SLICE_TILE`, the tiles' side and the workgroup's.
#import rust/constants.wgsl

override AXIS: u32 = 0u;

// Keep in sync with `lineao::passes::bilateral::BilateralUniform`.
struct BilateralUniform {
    view: ViewParams,
    radius: i32,
    // 1/(2σ_s²) and 1/(2σ_z²).
    spatial: f32,
    depth: f32,
    // 1: only the slices' pixels are blurred.
    slices_only: u32,
    // Tiles across and down, the tiles above and below a slice's that the x half also covers,
    // and the capacity of each list.
    tiles: vec4<u32>,
}

// The tiles to blur: how many for the x and the y half, then each half's list of tile indices
// (x at 0, y at `tiles.w`).
struct TileLists {
    counts: vec4<u32>,
    tiles: array<u32>,
}

@group(0) @binding(0) var<uniform> params: BilateralUniform;
@group(0) @binding(1) var nd0: texture_2d<f32>;
@group(0) @binding(2) var ao_in: texture_2d<f32>;
@group(0) @binding(3) var ao_out: texture_storage_2d<r32float, write>;
@group(0) @binding(4) var color: texture_2d<f32>;
@group(0) @binding(5) var<storage, read> lists: TileLists;

// The listing's own group (`list_tiles`, `dispatch_args`; group 0 is empty for them): the
// uniform again, the slices' marks, the lists written, and two indirect dispatches.
struct TileListsWrite {
    counts: array<atomic<u32>, 4>,
    tiles: array<u32>,
}
@group(1) @binding(0) var<uniform> tiling: BilateralUniform;
@group(1) @binding(1) var<storage, read> marked: array<u32>;
@group(1) @binding(2) var<storage, read_write> listing: TileListsWrite;
@group(1) @binding(3) var<storage, read_write> dispatches: array<u32, 6>;

// Blurs `pixel` along AXIS.
fn blur(pixel: vec2<i32>) {
    let size = vec2<i32>(textureDimensions(nd0));
    if any(pixel >= size) {
        return;
    }
    let here = textureLoad(nd0, pixel, 0);
    if nd_is_background(here) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    if params.slices_only != 0u && textureLoad(color, pixel, 0).a != 0.0 {
        textureStore(ao_out, pixel, textureLoad(ao_in, pixel, 0));
        return;
    }
    let z = linear_depth(params.view, here.w);
    let step = select(vec2<i32>(0, 1), vec2<i32>(1, 0), AXIS == 0u);
    var sum = 0.0;
    var weight = 0.0;
    for (var k = -params.radius; k <= params.radius; k++) {
        let s = pixel + k * step;
        if any(s < vec2<i32>(0)) || any(s >= size) {
            continue;
        }
        let nd = textureLoad(nd0, s, 0);
        if nd_is_background(nd) {
            continue;
        }
        let dz = linear_depth(params.view, nd.w) - z;
        let w = exp(-f32(k * k) * params.spatial - dz * dz * params.depth);
        sum += w * textureLoad(ao_in, s, 0).x;
        weight += w;
    }
    textureStore(ao_out, pixel, vec4<f32>(sum / weight, 0.0, 0.0, 0.0));
}

// Every pixel.
@compute @workgroup_size(8, 8)
fn bilateral(@builtin(global_invocation_id) id: vec3<u32>) {
    blur(vec2<i32>(id.xy));
}

// The pixels of the listed tiles (a workgroup a tile; the dispatch 65 535 wide).
@compute @workgroup_size(SLICE_TILE, SLICE_TILE)
fn bilateral_tiles(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_id) local: vec3<u32>) {
    let index = group.x + group.y * 65535u;
    if index >= lists.counts[AXIS] {
        return;
    }
    let tile = lists.tiles[AXIS * params.tiles.w + index];
    let corner = vec2<u32>(tile % params.tiles.x, tile / params.tiles.x) * SLICE_TILE;
    blur(vec2<i32>(corner + local.xy));
}

// Lists tile `id.x` for the y half where a slice marked it, for the x half where one marked it
// or a tile up to `tiles.z` above or below (whose rows the y half reads).
@compute @workgroup_size(64)
fn list_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    let tiles = tiling.tiles;
    let t = id.x;
    if t >= tiles.x * tiles.y {
        return;
    }
    let row = i32(t / tiles.x);
    let reach = i32(tiles.z);
    var near = false;
    for (var d = -reach; d <= reach; d++) {
        let r = row + d;
        if r >= 0 && r < i32(tiles.y) && marked[u32(i32(t) + d * i32(tiles.x))] != 0u {
            near = true;
        }
    }
    if near {
        listing.tiles[atomicAdd(&listing.counts[0], 1u)] = t;
    }
    if marked[t] != 0u {
        listing.tiles[tiles.w + atomicAdd(&listing.counts[1], 1u)] = t;
    }
}

// The two halves' indirect dispatches: a workgroup a listed tile, 65 535 wide.
@compute @workgroup_size(1)
fn dispatch_args() {
    for (var half = 0u; half < 2u; half++) {
        let count = atomicLoad(&listing.counts[half]);
        dispatches[3u * half] = min(count, 65535u);
        dispatches[3u * half + 1u] = (count + 65534u) / 65535u;
        dispatches[3u * half + 2u] = 1u;
    }
}
