// The moments pyramid of VO area sampling (Loos & Sloan §4.2, docs/reference.md "VO area"): level 0
// holds (E[z], E[z²]) of one pixel, z = −z_view in world units (the background at the far
// plane); level l is the binomial 5 x 5 of level l−1 at half resolution, centred at (2x, 2y) —
// the Gaussian the paper puts on its mip-map so that trilinear reads of a large footprint stay
// smooth. Moments filter linearly, so every level holds the mean and mean square of depth over
// a Gaussian footprint of about 2^l pixels. f32 throughout: E[z²] − E[z]² cancels badly in f16.
//
// A storage buffer rather than a mip-mapped texture: Mesa's lavapipe returns texels of the
// wrong mip when the level differs between the invocations of a SIMD group (VO area's level
// is per pixel), and a buffer lets every level be written and read in one binding.
#import shared/nd.wgsl
#import shared/view.wgsl
#import moments_layout.wgsl

@group(0) @binding(0) var<uniform> view: ViewParams;
@group(0) @binding(1) var<uniform> levels: array<vec4<u32>, MAX_MOMENT_LEVELS>;
// x: the level this dispatch writes.
@group(0) @binding(2) var<uniform> level: vec4<u32>;
@group(0) @binding(3) var nd0: texture_2d<f32>;
@group(0) @binding(4) var<storage, read_write> moments: array<vec2<f32>>;

// Level 0 from the ND map.
@compute @workgroup_size(8, 8, 1)
fn level0(@builtin(global_invocation_id) id: vec3<u32>) {
    let rect = levels[0];
    if (any(id.xy >= rect.yz)) {
        return;
    }
    let z = linear_depth(view, textureLoad(nd0, id.xy, 0).w);
    moments[moments_index(rect, vec2<i32>(id.xy))] = vec2<f32>(z, z * z);
}

// Level `level.x` from the one below.
@compute @workgroup_size(8, 8, 1)
fn downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    let rect = levels[level.x];
    if (any(id.xy >= rect.yz)) {
        return;
    }
    let src = levels[level.x - 1u];
    let centre = vec2<i32>(id.xy) * 2;
    var sum = vec2<f32>(0.0);
    for (var dy = 0; dy < 5; dy++) {
        var row = vec2<f32>(0.0);
        for (var dx = 0; dx < 5; dx++) {
            row += BINOMIAL[dx] * moments[moments_index(src, centre + vec2<i32>(dx - 2, dy - 2))];
        }
        sum += BINOMIAL[dy] * row;
    }
    moments[moments_index(rect, vec2<i32>(id.xy))] = sum;
}
