// The toy method of the registry's test: a quarter of occlusion on every geometry pixel.
#import shared/nd.wgsl

@group(0) @binding(0) var nd0: texture_2d<f32>;
@group(0) @binding(1) var ao: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn toy(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    if any(pixel >= vec2<i32>(textureDimensions(nd0))) {
        return;
    }
    let occlusion = select(0.25, 0.0, nd_is_background(textureLoad(nd0, pixel, 0)));
    textureStore(ao, pixel, vec4<f32>(occlusion));
}
