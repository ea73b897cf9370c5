// The pass of Volumetric Obscurance, line and area sampling alike (Loos & Sloan §4): its common
// bindings and its entry point `vo`. Per pixel: the background stays unoccluded; otherwise the
// pixel's linear depth, zoom and 4 × 4 tile direction, and the obscurance of the sphere of the
// first radius, combined with the second's when RADII = 2 (Fig. 8).
//
// A fragment, not a module: the file that imports it defines the one thing that differs between
// the methods, `fn obscurance(pixel, here, depth, zoom, u, radius) -> f32`, and binds what its
// sampling reads from binding 5 on (`lineao::shader::FRAGMENTS`; validated within its importers).
#import shared/vo.wgsl

override RADII: u32 = 1u;

@group(0) @binding(0) var<uniform> params: VoUniform;
// samples[0..16]: (x, y, A_i, w: the method's own); tile[16..32]: (u.x, u.y) unit 2D directions.
@group(0) @binding(1) var<uniform> tables: array<vec4<f32>, 32>;
@group(0) @binding(2) var nd0: texture_2d<f32>;
@group(0) @binding(3) var zoom_map: texture_2d<f32>;
@group(0) @binding(4) var ao_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn vo(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(nd0);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = id.xy;
    let here = textureLoad(nd0, pixel, 0);
    if nd_is_background(here) {
        textureStore(ao_out, pixel, vec4<f32>(0.0));
        return;
    }
    let depth = linear_depth(params.view, here.w);
    let zoom = textureLoad(zoom_map, pixel, 0).x;
    let u = tables[vo_tile_index(pixel, params.noise_origin)].xy;
    var ao = obscurance(pixel, here, depth, zoom, u, params.radius.x);
    if RADII == 2u {
        ao = vo_combine(ao, obscurance(pixel, here, depth, zoom, u, params.radius.y), params.combine);
    }
    textureStore(ao_out, pixel, vec4<f32>(ao, 0.0, 0.0, 0.0));
}
