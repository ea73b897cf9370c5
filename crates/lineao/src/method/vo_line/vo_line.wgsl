// Volumetric Obscurance with line samples (Loos & Sloan 2010, §4.1, §4.3, §4.4): the fraction
// of a sphere of radius R around P that the depth buffer leaves free, integrated analytically
// along N vertical lines through the sphere at disk points s_i with weights A_i:
//
//   ao(P) = 1 − Σ A_i |free ∩ allowed|_i / Σ A_i |allowed|_i
//   d_r = (depth at P + (s.x, −s.y) R z(P)/zoom_unit − depth(P)) / R, a step (σ = 0)
//
// Without the clamp a plane facing the camera is exactly half free; with it, wholly free.
// Each sample is taken where the depth it reads lies: at the centre of the texel under s,
// s_t = (texel − pixel) / (R z(P)/zoom_unit) (y flipped), with its own half chord
// √(1 − |s_t|²). The depth of that centre is the surface's there, so a tilted plane stays
// wholly free under the clamp; measured at s itself, half a texel's depth step put the plane
// in front of the sample half the time. The normal clamp cuts each chord where the sample's
// own view ray, through the texel's centre, crosses P's tangent plane (`tangent_plane_depth`:
// D = n·P / n·r along the ray r; orthographic (n.xy·s − n·P) / n_z); cut at s · n.xy / n_z
// as if rays were parallel, open ground darkened by 5 %.
// Each pixel reflects its samples about a 2D direction from a 4 x 4 tile. With RADII = 2 the
// sphere is evaluated at two radii and the results combined (Fig. 8).
#import shared/nd.wgsl
#import shared/vo_pass.wgsl

// The tables' w: z_s = √(1 − x² − y²), each sample's half chord.
fn obscurance(pixel: vec2<u32>, here: vec4<f32>, depth: f32, zoom: f32, u: vec2<f32>, radius: f32) -> f32 {
    let v = params.view;
    let scale = radius * zoom / params.zoom_unit;
    let thickness = params.thickness / radius;
    // d_r = (linear depth at the sample − depth(P)) / R as one multiply-add of the stored depth.
    let d_scale = (v.far - v.near) / radius;
    let d_offset = (v.near - depth) / radius;
    let clamp_on = params.normal_clamp != 0u;
    let p = view_position(v, pixel, depth);
    let last = vec2<f32>(textureDimensions(nd0)) - 1.0;
    var sums = vec2<f32>(0.0);
    for (var i = 0u; i < params.samples; i++) {
        let sample = tables[i];
        let s = vo_reflect(sample.xy, u);
        let at = vec2<f32>(f32(pixel.x) + 0.5 + s.x * scale, f32(pixel.y) + 0.5 - s.y * scale);
        let t = clamp(floor(at), vec2<f32>(0.0), last);
        let d_r = textureLoad(nd0, vec2<i32>(t), 0).w * d_scale + d_offset;
        let s_t = vec2<f32>(t.x - f32(pixel.x), f32(pixel.y) - t.y) / max(scale, 1e-20);
        let z_s = sqrt(max(1.0 - dot(s_t, s_t), 0.0));
        var chord = vec2<f32>(-z_s, z_s);
        if clamp_on {
            chord.y = min(z_s, (tangent_plane_depth(v, p, here.xyz, t + 0.5) - depth) / radius);
        }
        sums += sample.z * vo_sample(chord, d_r, 0.0, thickness);
    }
    return vo_ao(sums);
}
