// The depth pyramid the line cull tests against (`lineao::passes::depth_pyramid`): level 0 the
// hardware depth, each further level ⌈W/2⌉ × ⌈H/2⌉ with the *largest* (farthest) depth of the
// up to 2 × 2 texels below it, so texel (x, y) of level L holds the farthest depth of every pixel
// in [x·2^L, (x+1)·2^L) × [y·2^L, (y+1)·2^L): anything nearer than that is in front of all of them.
// All levels lie in one buffer, row by row, level after level.

struct Level {
    // Where the level read from and the level written start in `pyramid`, and their sizes.
    read_at: u32,
    write_at: u32,
    read_size: vec2<u32>,
    write_size: vec2<u32>,
    _pad: vec2<u32>,
}

@group(0) @binding(0) var<uniform> level: Level;
@group(0) @binding(1) var depth: texture_depth_2d;
@group(0) @binding(2) var<storage, read_write> pyramid: array<f32>;

// Level 0: the depth as it is.
@compute @workgroup_size(8, 8)
fn copy_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= level.write_size) {
        return;
    }
    pyramid[level.write_at + id.y * level.write_size.x + id.x] = textureLoad(depth, id.xy, 0);
}

// Level L + 1 from level L: the farthest of the texels below (one or two where an odd size ends).
@compute @workgroup_size(8, 8)
fn reduce_max(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= level.write_size) {
        return;
    }
    let last = level.read_size - 1u;
    let a = min(2u * id.xy, last);
    let b = min(2u * id.xy + 1u, last);
    let row_a = level.read_at + a.y * level.read_size.x;
    let row_b = level.read_at + b.y * level.read_size.x;
    let farthest = max(max(pyramid[row_a + a.x], pyramid[row_a + b.x]), max(pyramid[row_b + a.x], pyramid[row_b + b.x]));
    pyramid[level.write_at + id.y * level.write_size.x + id.x] = farthest;
}
