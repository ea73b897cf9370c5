// The billboard a tube segment is ray-cast on (`tubes.wgsl`), and what the cull bounds it by
// (`cull.wgsl`): on screen the disks of its two end spheres, hulled by a rectangle along the
// segment a pixel wider all round; in depth the solid's nearest point, the nearer end
// sphere's front, which the fragment shader's written depth is never nearer than.
#import shared/geometry.wgsl

// A bound of the screen radius in pixels of a sphere of radius `r` at view position `p`:
// r f / (d − r) at depth d, stretched by (|p| / d)² toward the image's edges (a sphere off the
// optical axis projects to an ellipse).
fn screen_radius(p: vec3<f32>, r: f32) -> f32 {
    if is_orthographic() {
        return r * frame.f_px;
    }
    let d = -p.z;
    if d <= r * 1.0001 {
        return 2.0 * max(frame.viewport.x, frame.viewport.y);
    }
    let stretch = dot(p, p) / (d * d);
    return r * frame.f_px / (d - r) * stretch;
}

fn to_pixels(clip: vec4<f32>) -> vec2<f32> {
    return (clip.xy / clip.w * vec2<f32>(0.5, -0.5) + 0.5) * frame.viewport;
}

// The billboard of the segment between view positions `a` and `b` with radii `ra`, `rb`: its
// ends in pixels, how far it reaches beyond each (pixels), and its depth (NDC).
struct Billboard {
    pa: vec2<f32>,
    pb: vec2<f32>,
    reach_a: f32,
    reach_b: f32,
    depth: f32,
}

fn billboard(a: vec3<f32>, b: vec3<f32>, ra: f32, rb: f32) -> Billboard {
    var out: Billboard;
    out.pa = to_pixels(frame.proj * vec4<f32>(a, 1.0));
    out.pb = to_pixels(frame.proj * vec4<f32>(b, 1.0));
    out.reach_a = screen_radius(a, ra) + 1.0;
    out.reach_b = screen_radius(b, rb) + 1.0;
    // At the solid's nearest depth (the nearer end sphere's front).
    let front = min(-a.z - ra, -b.z - rb);
    let near_clip = frame.proj * vec4<f32>(0.0, 0.0, -max(front, 1e-6), 1.0);
    out.depth = clamp(near_clip.z / near_clip.w, 0.0, 1.0);
    return out;
}

// Whether an end at view position `p` lies behind the eye: its segment draws no billboard.
fn behind_eye(p: vec3<f32>) -> bool {
    return !is_orthographic() && -p.z <= 0.0;
}
