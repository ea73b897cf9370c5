// Scene lights, shared by the line renderer (illuminated-lines specular) and LineAO (Eq. 14-15).
// Keep in sync with `lineao::lighting::LightingUniform`.
const MAX_LIGHTS: u32 = 4u;

struct Lighting {
    // xyz: unit view-space direction toward the light, w: intensity I.
    lights: array<vec4<f32>, 4>,
    count: u32,
    kd: f32,
    ks: f32,
    shininess: f32,
}

// max(x, 0)^alpha, defined as 0 at x <= 0 (pow(0, a) is implementation-defined in WGSL).
fn clamped_pow(x: f32, alpha: f32) -> f32 {
    return select(0.0, pow(x, alpha), x > 0.0);
}
