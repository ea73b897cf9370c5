// Object-space AO per pixel (seed 000 Eq. 4–5) of the interpolated octant visibilities V_o of the
// `octants` target and the ND map's normal (`shared/object_ao.wgsl`). See
// `lineao::passes::volume_ao`.
#import shared/nd.wgsl
#import shared/object_ao.wgsl

@group(0) @binding(0) var<uniform> volume_params: VolumeAoUniform;
@group(0) @binding(1) var nd0: texture_2d<f32>;
@group(0) @binding(2) var octants: texture_2d<u32>;
@group(0) @binding(3) var<storage, read> volume_table: array<vec4<f32>>;
@group(0) @binding(4) var ao_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn volume_ao(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(nd0);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let nd = textureLoad(nd0, pixel, 0);
    if nd_is_background(nd) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    let ao = object_ao(nd.xyz, textureLoad(octants, pixel, 0).xy);
    textureStore(ao_out, pixel, vec4<f32>(ao, 0.0, 0.0, 0.0));
}
