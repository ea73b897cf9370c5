// ND pyramid (paper §3.4, docs/reference.md "Pyramid"): level j is the separable binomial
// [1 4 6 4 1]/16 of level j-1 centred at texel (2x, 2y), clamp-to-edge, over all four channels
// (background included, so sparse lines fade and dense bundles merge at coarse levels). The
// filtered normal is renormalized, or set to zero (background) when shorter than 1e-6.
#import shared/nd.wgsl

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8, 1)
fn downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id.xy >= textureDimensions(dst))) {
        return;
    }
    let sum = binomial_5x5(src, vec2<i32>(id.xy) * 2);
    let len = length(sum.xyz);
    let n = select(vec3<f32>(0.0), sum.xyz / len, len > 1e-6);
    textureStore(dst, vec2<i32>(id.xy), vec4<f32>(n, sum.w));
}
