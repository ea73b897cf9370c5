// Anatomy slices (`lineao::passes::slices`): one convex polygon an axis, the rectangle of the
// voxel centres or (where voxels without data are transparent) an outline around the data
// near the plane, drawn as a fan of triangles; each fragment
// samples the volume trilinearly between voxel centres through the inverse affine and writes
// the G-buffer of docs/reference.md with the value through the window and colormap (`base_color`,
// color mode 2), unlit, the plane's normal turned toward the eye. Transparent: no fragment
// where the voxels without data (0 or NaN) weigh half the sample or more. The sample: one
// filtered sample where the device filters f32 textures (`fs_slice_filtered`: an `Rg32Float`
// texel, the value and 1 where the voxel holds data), else eight `textureLoad`s of an
// `R32Float` one (`fs_slice`).
#import shared/geometry.wgsl
// SLICE_TILE: `lineao::targets::SLICE_TILE`; OUTLINE_SIDES: `lineao::passes::slices::OUTLINE_SIDES`.
#import rust/constants.wgsl

// Keep in sync with `lineao::passes::slices::SliceUniform`.
struct SliceUniform {
    world_to_voxel: mat4x4<f32>,
    // xyz: where each axis's slice lies (world units).
    positions: vec4<f32>,
    // xyz: 1 where the axis shows a slice; w: 1 where voxels without data are transparent.
    shown: vec4<u32>,
    // xyz: the last voxel index on each axis.
    last_voxel: vec4<f32>,
    // Each axis's polygon in its plane: OUTLINE_SIDES corners (u, w), two a vec4.
    outline: array<vec4<f32>, 3 * OUTLINE_SIDES / 2>,
}

// r: the value; g (where the device filters f32): 1 where the voxel holds data (finite, not 0).
@group(1) @binding(0) var volume: texture_3d<f32>;
@group(1) @binding(1) var<uniform> slice: SliceUniform;
// Trilinear, clamped to the edge.
@group(1) @binding(2) var trilinear_sampler: sampler;
// A u32 per SLICE_TILE² tile of the guard-banded target, row-major, set where a slice's fragment
// falls (`lineao::targets::FrameTargets::slice_tiles`): the bilateral blur runs there alone.
@group(2) @binding(0) var<storage, read_write> tiles: array<u32>;

struct SliceOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) world: vec3<f32>,
    @location(2) @interpolate(flat) axis: u32,
}

// Vertex v of axis `axis`'s polygon, a fan (corner 0, corner t + 1, corner t + 2 make triangle
// t = v / 3); every vertex at the origin (no area) where the axis shows no slice.
@vertex
fn vs_slice(@builtin(vertex_index) v: u32, @builtin(instance_index) axis: u32) -> SliceOut {
    var out: SliceOut;
    out.axis = axis;
    if slice.shown[axis] == 0u {
        out.clip = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        return out;
    }
    let corner = select(v / 3u + v % 3u, 0u, v % 3u == 0u);
    let pair = slice.outline[axis * (OUTLINE_SIDES / 2u) + corner / 2u];
    let c = select(pair.xy, pair.zw, corner % 2u == 1u);
    let u = (axis + 1u) % 3u;
    let w = (axis + 2u) % 3u;
    var world = vec3<f32>(0.0);
    world[axis] = slice.positions[axis];
    world[u] = c.x;
    world[w] = c.y;
    let view_pos = frame.view * vec4<f32>(world, 1.0);
    out.clip = frame.proj * view_pos;
    out.view_pos = view_pos.xyz;
    out.world = world;
    return out;
}

// The volume at voxel coordinates `x` (within the box of the voxel centres), trilinear, and
// the weight of its voxels that hold data (finite, not 0) in that sum.
fn trilinear(x: vec3<f32>) -> vec2<f32> {
    let last = vec3<i32>(slice.last_voxel.xyz);
    let i0 = clamp(vec3<i32>(floor(x)), vec3<i32>(0), last);
    let i1 = min(i0 + vec3<i32>(1), last);
    let f = clamp(x - vec3<f32>(i0), vec3<f32>(0.0), vec3<f32>(1.0));
    var sum = vec2<f32>(0.0);
    for (var corner = 0u; corner < 8u; corner++) {
        let pick = vec3<bool>((corner & 1u) != 0u, (corner & 2u) != 0u, (corner & 4u) != 0u);
        let weight = select(1.0 - f, f, pick);
        let v = textureLoad(volume, select(i0, i1, pick), 0).r;
        // Finite and not 0: its bits' exponent is not all ones, and they are not ±0.
        let bits = bitcast<u32>(v) & 0x7fffffffu;
        let data = select(0.0, 1.0, bits != 0u && bits < 0x7f800000u);
        sum += weight.x * weight.y * weight.z * vec2<f32>(v, data);
    }
    return sum;
}

// `trilinear` by the texture units: the value and the data's mark, sampled once.
fn filtered(x: vec3<f32>) -> vec2<f32> {
    let uvw = (x + 0.5) / (slice.last_voxel.xyz + 1.0);
    return textureSampleLevel(volume, trilinear_sampler, uvw, 0.0).rg;
}

// The fragment's voxel coordinates; none outside the box of the voxel centres (a little slack
// for rounding on its faces).
fn voxel(in: SliceOut) -> vec3<f32> {
    let x = (slice.world_to_voxel * vec4<f32>(in.world, 1.0)).xyz;
    let slack = 1e-3;
    if any(x < vec3<f32>(-slack)) || any(x > slice.last_voxel.xyz + vec3<f32>(slack)) {
        discard;
    }
    return x;
}

// The G-buffer of the fragment whose volume `sample` is (value, weight of data).
fn slice_gbuffer(in: SliceOut, sample: vec2<f32>) -> GBuffer {
    if slice.shown.w != 0u && sample.y < 0.5 {
        discard;
    }
    let tile = vec2<u32>(in.clip.xy) / SLICE_TILE;
    let index = tile.y * ((u32(frame.viewport.x) + SLICE_TILE - 1u) / SLICE_TILE) + tile.x;
    if index < arrayLength(&tiles) {
        tiles[index] = 1u;
    }
    var axis_world = vec3<f32>(0.0);
    axis_world[in.axis] = 1.0;
    let n = (frame.view * vec4<f32>(axis_world, 0.0)).xyz;
    var out: GBuffer;
    out.nd = gbuffer_nd(in.view_pos, n, frame.near, frame.far, is_orthographic());
    // Alpha 0 marks a slice's pixel (every other writer of the G-buffer writes 1): the chain's
    // bilateral blur smooths the occlusion there (`shaders/bilateral.wgsl`, `slices_only`).
    out.color = vec4<f32>(base_color(vec3<f32>(0.0), sample.x), 0.0);
    out.zoom = gbuffer_zoom(in.view_pos, frame.f_px, frame.zoom_unit, is_orthographic());
    out.specular = 0.0;
    return out;
}

@fragment
fn fs_slice(in: SliceOut) -> GBuffer {
    return slice_gbuffer(in, trilinear(voxel(in)));
}

@fragment
fn fs_slice_filtered(in: SliceOut) -> GBuffer {
    return slice_gbuffer(in, filtered(voxel(in)));
}

// Slices are not in the lines' density volume: fully visible to object-space AO.
@fragment
fn fs_slice_octants(in: SliceOut) -> GBufferOctants {
    return with_octants(slice_gbuffer(in, trilinear(voxel(in))), vec4<f32>(1.0), vec4<f32>(1.0));
}

@fragment
fn fs_slice_filtered_octants(in: SliceOut) -> GBufferOctants {
    return with_octants(slice_gbuffer(in, filtered(voxel(in))), vec4<f32>(1.0), vec4<f32>(1.0));
}
