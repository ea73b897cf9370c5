// The moments pyramid's layout (CONTRACT.md "VO area"; `lineao::targets::Moments`): every level
// in one buffer of (E[z], E[z²]), level l at `levels[l].x` with `levels[l].yz` texels, row-major.
// Keep MAX_MOMENT_LEVELS in sync with `lineao::method::vo_area::moments::MAX_MOMENT_LEVELS`.
const MAX_MOMENT_LEVELS: u32 = 16u;

// Index of `texel` of the level `rect` = (offset, width, height, _), clamped to the level.
fn moments_index(rect: vec4<u32>, texel: vec2<i32>) -> u32 {
    let t = clamp(texel, vec2<i32>(0), vec2<i32>(rect.yz) - 1);
    return rect.x + u32(t.y) * rect.y + u32(t.x);
}
