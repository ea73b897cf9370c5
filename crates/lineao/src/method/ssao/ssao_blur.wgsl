// The 4 x 4 blur that matches SSAO's 4 x 4 rotation tile: the mean over x-2..=x+1,
// y-2..=y+1 (each rotation exactly once) of the geometry pixels in the window.
#import shared/nd.wgsl

@group(0) @binding(0) var nd0: texture_2d<f32>;
@group(0) @binding(1) var ao_in: texture_2d<f32>;
@group(0) @binding(2) var ao_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn blur(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(nd0));
    let pixel = vec2<i32>(id.xy);
    if pixel.x >= size.x || pixel.y >= size.y {
        return;
    }
    if nd_is_background(textureLoad(nd0, pixel, 0)) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    var sum = 0.0;
    var count = 0u;
    for (var dy = -2; dy <= 1; dy++) {
        for (var dx = -2; dx <= 1; dx++) {
            let s = pixel + vec2<i32>(dx, dy);
            if any(s < vec2<i32>(0)) || any(s >= size) {
                continue;
            }
            if !nd_is_background(textureLoad(nd0, s, 0)) {
                sum += textureLoad(ao_in, s, 0).x;
                count += 1u;
            }
        }
    }
    textureStore(ao_out, pixel, vec4<f32>(sum / f32(count), 0.0, 0.0, 0.0));
}
