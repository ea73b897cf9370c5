// The strip lineao drew before clusters (`lineao::line_geometry::strip`, feature `reference`):
// every point twice in a vertex buffer, its tangent as snorm16; the lines' own fragment shader.
// Kept as the baseline the clusters are tested and measured against.
#import lines.wgsl

struct StripVertex {
    @location(0) p: vec3<f32>,
    // xyz: unit world-space tangent; w: the side (> 0 left, < 0 right).
    @location(1) t: vec4<f32>,
}

@vertex
fn vs_strip(v: StripVertex) -> VsOut {
    return line_vertex(v.p, v.t.xyz, sign(v.t.w), 0.0);
}
