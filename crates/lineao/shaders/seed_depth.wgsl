// A host's depth seeds the G-buffer's (`lineao::passes::seed_depth`): each pixel of the
// visible part gets the chain's depth of the view-space z the host's depth there stands for,
// pushed a little farther (never nearer than the host's picture); where the host drew nothing
// (its cleared depth, infinity, behind the eye) and in the guard band, the far plane.
#import shared/fullscreen.wgsl

// Keep in sync with `lineao::passes::seed_depth::SeedUniform`.
struct Seed {
    guard: vec2<u32>,
    // The host's (visible) size.
    size: vec2<u32>,
    // The z and w rows of the host's projection and of the chain's: depth = (x·z + y) / (z·z + w)
    // of a view-space z.
    host_rows: vec4<f32>,
    chain_rows: vec4<f32>,
    // The host's depth where it drew nothing (1 standard, 0 reversed-Z).
    cleared: f32,
    _pad0: u32,
    _pad1: vec2<u32>,
}

@group(0) @binding(0) var<uniform> seed: Seed;
@group(0) @binding(1) var host_depth: texture_depth_2d;

// How much farther than the host's surface the seeded depth lies (relative view distance): the
// two projections round differently, and a line in front of the host's picture must stay.
const FARTHER: f32 = 1e-5;

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(vertex_index);
}

@fragment
fn fs_seed(@builtin(position) position: vec4<f32>) -> @builtin(frag_depth) f32 {
    let pixel = vec2<i32>(position.xy) - vec2<i32>(seed.guard);
    if any(pixel < vec2<i32>(0)) || any(pixel >= vec2<i32>(seed.size)) {
        return 1.0;
    }
    let d = textureLoad(host_depth, pixel, 0);
    if d == seed.cleared {
        return 1.0;
    }
    // d = (a z + b) / (c z + e), so z = (b − e d) / (c d − a).
    let h = seed.host_rows;
    let z = (h.y - h.w * d) / (h.z * d - h.x);
    // Behind the eye, at infinity or not a number: nothing to hide behind.
    if !(z < 0.0 && z > -3.0e38) {
        return 1.0;
    }
    let farther = z * (1.0 + FARTHER);
    let c = seed.chain_rows;
    return clamp((c.x * farther + c.y) / (c.z * farther + c.w), 0.0, 1.0);
}
