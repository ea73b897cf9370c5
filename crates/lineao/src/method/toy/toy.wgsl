// The toy method of the registry's test: the same occlusion on every geometry pixel
// (`ToySettings::occlusion`, in lineao::method::toy).
#import shared/nd.wgsl

struct ToyUniform {
    occlusion: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

@group(0) @binding(0) var<uniform> params: ToyUniform;
@group(0) @binding(1) var nd0: texture_2d<f32>;
@group(0) @binding(2) var ao: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn toy(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    if any(pixel >= vec2<i32>(textureDimensions(nd0))) {
        return;
    }
    let occlusion = select(params.occlusion, 0.0, nd_is_background(textureLoad(nd0, pixel, 0)));
    textureStore(ao, pixel, vec4<f32>(occlusion));
}
