// From a pixel and its normalized depth to view space and back (docs/reference.md "Coordinates").
// Keep in sync with `lineao::reference::ViewParams`.
struct ViewParams {
    // −z_view at normalized depth 0 and 1.
    near: f32,
    far: f32,
    // Focal length in pixels (perspective) or pixels per world unit (orthographic).
    f_px: f32,
    orthographic: u32,
    // The optical axis in pixels of the guard-banded image.
    center: vec2<f32>,
    _pad: vec2<f32>,
}

fn linear_depth(v: ViewParams, d: f32) -> f32 {
    return v.near + d * (v.far - v.near);
}

fn view_position(v: ViewParams, pixel: vec2<u32>, depth: f32) -> vec3<f32> {
    let sx = (f32(pixel.x) + 0.5 - v.center.x) / v.f_px;
    let sy = (v.center.y - (f32(pixel.y) + 0.5)) / v.f_px;
    if v.orthographic != 0u {
        return vec3<f32>(sx, sy, -depth);
    }
    return vec3<f32>(sx * depth, sy * depth, -depth);
}

fn project(v: ViewParams, q: vec3<f32>) -> vec2<f32> {
    let depth = -q.z;
    if v.orthographic != 0u {
        return vec2<f32>(v.center.x + v.f_px * q.x, v.center.y - v.f_px * q.y);
    }
    return vec2<f32>(v.center.x + v.f_px * q.x / depth, v.center.y - v.f_px * q.y / depth);
}
