// The ND map (docs/reference.md): rgb = unit view-space normal facing the eye, a = normalized linear
// depth in [0, 1]. Background: normal (0, 0, 0), depth 1.

// Maximum number of ND pyramid levels a shader binds (`s_r` <= MAX_LEVELS).
const MAX_LEVELS: u32 = 5u;

fn nd_is_background(nd: vec4<f32>) -> bool {
    return all(nd.xyz == vec3<f32>(0.0));
}

// Size of each pyramid level, padded to MAX_LEVELS with the last level.
// Keep in sync with `lineao::targets::LevelsUniform`.
struct Levels {
    // xy: size_j / size_0.
    scale: array<vec4<f32>, 5>,
    // xy: size of level j in texels.
    size: array<vec4<u32>, 5>,
}

// Nearest texel of a pyramid level for full-resolution pixel `pixel` displaced by `offset` pixels:
// floor((P + 0.5 + offset) * size_j / size_0), clamped to the level (docs/reference.md "Addressing").
// `scale` is size_j / size_0, computed once on the CPU so that both sides use the same f32.
fn level_texel(pixel: vec2<u32>, offset: vec2<f32>, scale: vec2<f32>, size: vec2<u32>) -> vec2<i32> {
    let uv = (vec2<f32>(pixel) + 0.5 + offset) * scale;
    let texel = vec2<i32>(floor(uv));
    return clamp(texel, vec2<i32>(0), vec2<i32>(size) - 1);
}

const BINOMIAL: array<f32, 5> = array<f32, 5>(0.0625, 0.25, 0.375, 0.25, 0.0625);

// The separable binomial [1 4 6 4 1]/16 of `src` around `centre`, clamp-to-edge: one step of a
// Gaussian pyramid when `centre` is twice the destination texel.
fn binomial_5x5(src: texture_2d<f32>, centre: vec2<i32>) -> vec4<f32> {
    let src_max = vec2<i32>(textureDimensions(src)) - 1;
    var sum = vec4<f32>(0.0);
    for (var dy = 0; dy < 5; dy++) {
        var row = vec4<f32>(0.0);
        for (var dx = 0; dx < 5; dx++) {
            let texel = clamp(centre + vec2<i32>(dx - 2, dy - 2), vec2<i32>(0), src_max);
            row += BINOMIAL[dx] * textureLoad(src, texel, 0);
        }
        sum += BINOMIAL[dy] * row;
    }
    return sum;
}
