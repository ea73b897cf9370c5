// Separable bilateral blur (a depth-aware Gaussian, as the VO paper uses after its samples):
// one axis per pipeline (AXIS 0 = x, 1 = y), applied x then y. Each geometry neighbour k
// pixels away weighs exp(−k²/(2σ_s²) − Δz²/(2σ_z²)), Δz its linear depth minus the centre's in
// world units; the background neither receives nor gives occlusion.
//
// Over anatomy slices (`slices_only`) only the slices' pixels (the G-buffer colour's alpha 0,
// `shaders/slices.wgsl`) receive: every other keeps its occlusion. Then `list_tiles` lists the
// SLICE_TILE² tiles that the slices' fragments marked and that still show a slice's pixel,
// `dispatch_args` turns the count into an indirect dispatch, and `bilateral_tiles` runs a
// workgroup per listed tile, for each half (both outputs hold the raw occlusion elsewhere,
// copied: no slice's pixel is there).
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
    // Tiles across and down (zw spare).
    tiles: vec4<u32>,
}

// The tiles to blur: how many (x; yzw spare), then their indices.
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
// uniform again, the slices' marks, the list written, the halves' indirect dispatch, and the
// G-buffer's colour again.
struct TileListsWrite {
    counts: array<atomic<u32>, 4>,
    tiles: array<u32>,
}
@group(1) @binding(0) var<uniform> tiling: BilateralUniform;
@group(1) @binding(1) var<storage, read> marked: array<u32>;
@group(1) @binding(2) var<storage, read_write> listing: TileListsWrite;
@group(1) @binding(3) var<storage, read_write> dispatches: array<u32, 3>;
@group(1) @binding(4) var shown_color: texture_2d<f32>;

// Blurs `pixel` along AXIS.
fn blur(pixel: vec2<i32>) {
    let size = vec2<i32>(textureDimensions(nd0));
    if any(pixel >= size) {
        return;
    }
    // Over the slices every other pixel keeps its occlusion, copied before the halves.
    let receives = params.slices_only == 0u || textureLoad(color, pixel, 0).a == 0.0;
    if !receives {
        return;
    }
    let here = textureLoad(nd0, pixel, 0);
    if nd_is_background(here) {
        if params.slices_only == 0u {
            textureStore(ao_out, pixel, vec4<f32>(0.0));
        }
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
    if index >= lists.counts.x {
        return;
    }
    let tile = lists.tiles[index];
    let corner = vec2<u32>(tile % params.tiles.x, tile / params.tiles.x) * SLICE_TILE;
    blur(vec2<i32>(corner + local.xy));
}

// Lists tile `id.x` where a slice marked it and one of its pixels shows a slice still (the
// slices are drawn first: the lines in front hid every pixel of half the marked tiles).
@compute @workgroup_size(64)
fn list_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = id.x;
    if t >= tiling.tiles.x * tiling.tiles.y || marked[t] == 0u {
        return;
    }
    let corner = vec2<u32>(t % tiling.tiles.x, t / tiling.tiles.x) * SLICE_TILE;
    let end = min(corner + SLICE_TILE, textureDimensions(shown_color));
    for (var y = corner.y; y < end.y; y++) {
        for (var x = corner.x; x < end.x; x++) {
            if textureLoad(shown_color, vec2<u32>(x, y), 0).a == 0.0 {
                listing.tiles[atomicAdd(&listing.counts[0], 1u)] = t;
                return;
            }
        }
    }
}

// The halves' indirect dispatch: a workgroup a listed tile, 65 535 wide.
@compute @workgroup_size(1)
fn dispatch_args() {
    let count = atomicLoad(&listing.counts[0]);
    dispatches[0] = min(count, 65535u);
    dispatches[1] = (count + 65534u) / 65535u;
    dispatches[2] = 1u;
}
