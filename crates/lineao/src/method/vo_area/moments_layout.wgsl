// The moments pyramid's layout (docs/reference.md "VO area"; `lineao::method::vo_area::moments::Moments`): every level
// in one buffer of (E[z], E[z²]), level l at `levels[l].x` with `levels[l].yz` texels, row-major.
// MAX_MOMENT_LEVELS: Rust's `lineao::method::vo_area::moments::MAX_MOMENT_LEVELS`.
#import rust/constants.wgsl

// Index of `texel` of the level `rect` = (offset, width, height, _), clamped to the level.
fn moments_index(rect: vec4<u32>, texel: vec2<i32>) -> u32 {
    let t = clamp(texel, vec2<i32>(0), vec2<i32>(rect.yz) - 1);
    return rect.x + u32(t.y) * rect.y + u32(t.x);
}
