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
    // 0: the maximum-principle specular only, 1: cylinder-averaged diffuse and specular.
    line_shading: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// The lighting's shape as pipeline constants (`lineao::lighting::LightingShape`), so that what
// a uniform would decide per pixel is straight code: a CPU rasterizer runs a loop of a uniform
// count, and both sides of a branch on a uniform, for every lane (LineAO 3x faster with its
// light loop unrolled; lines 1.65x, tubes 1.32x with theirs, lavapipe, `lineao bench`).
// ANY: decided by the uniform instead (a pipeline made for every lighting); the functions
// below take the uniform's value.
const ANY: u32 = 0xffffffffu;
// The number of lights, <= MAX_LIGHTS.
override LIGHTS: u32 = ANY;
// The specular exponent α when it is a whole number in 1..512 (then raised by squaring,
// `whole_pow`: LineAO 17 % faster on lavapipe at α = 32), 0 to use `lighting.shininess`.
override SHININESS_WHOLE: u32 = 0u;
// How lines are lit (`lighting.line_shading`'s values).
override LINE_SHADING: u32 = ANY;

fn light_count(uniform: Lighting) -> u32 {
    return select(LIGHTS, uniform.count, LIGHTS == ANY);
}

fn line_shading(uniform: Lighting) -> u32 {
    return select(LINE_SHADING, uniform.line_shading, LINE_SHADING == ANY);
}

// max(x, 0)^alpha for the shininess alpha of the uniform.
fn specular_pow(x: f32, alpha: f32) -> f32 {
    if SHININESS_WHOLE == 0u {
        return clamped_pow(x, alpha);
    }
    return whole_pow(x, SHININESS_WHOLE);
}

// max(x, 0)^alpha, defined as 0 at x <= 0 (pow(0, a) is implementation-defined in WGSL).
fn clamped_pow(x: f32, alpha: f32) -> f32 {
    return select(0.0, pow(x, alpha), x > 0.0);
}

// clamped_pow for a whole exponent 1 <= n < 512 by squaring. Called with a constant n, the
// loop unrolls and the bit tests fold away: five multiplies for n = 32, where pow is
// exp2(n log2 x) in a software rasterizer's polynomials.
fn whole_pow(x: f32, n: u32) -> f32 {
    var result = 1.0;
    var power = max(x, 0.0);
    for (var bit = 0u; bit < 9u; bit++) {
        if ((n >> bit) & 1u) != 0u {
            result *= power;
        }
        power *= power;
    }
    return result;
}

// Illuminated lines (`lineao::lighting` derives both): for unit l, v toward the light and the
// eye and unit tangent t, (diffuse, specular) before intensity and kd/ks. Shading 0: Zöckler's
// maximum principle (diffuse 0); 1: Mallo et al.'s average over the visible half cylinder
// (diffuse in closed form, specular by 16-point Gauss-Legendre around the highlight).
fn illuminated_line(shading: u32, l: vec3<f32>, v: vec3<f32>, t: vec3<f32>, n: f32) -> vec2<f32> {
    let l_t = dot(l, t);
    let v_t = dot(v, t);
    let peak = sqrt(max(1.0 - l_t * l_t, 0.0)) * sqrt(max(1.0 - v_t * v_t, 0.0)) - l_t * v_t;
    if shading == 0u {
        return vec2<f32>(0.0, specular_pow(peak, n));
    }
    let l_perp = l - l_t * t;
    let v_perp = v - v_t * t;
    let a = length(l_perp);
    let b = length(v_perp);
    let ab = a * b;
    let cos_alpha = select(0.0, clamp(dot(l_perp, v_perp) / ab, -1.0, 1.0), ab > 1e-8);
    let alpha = acos(cos_alpha);
    let pi = 3.14159265358979;
    let diffuse = 0.25 * a * (sqrt(1.0 - cos_alpha * cos_alpha) + (pi - alpha) * cos_alpha);
    // The visible, lit arc around the highlight is u in [-c, c]; g reaches 0 at the root; the
    // highlight's width is sigma.
    let c = 0.5 * (pi - alpha);
    let root = 0.5 * acos(clamp(l_t * v_t / ab, -1.0, 1.0));
    let h = select(c, min(min(c, root), 5.0 * sqrt(max(peak, 0.0) / (4.0 * n * ab))), ab > 1e-12);
    // 16-point Gauss-Legendre on [-h, h]: the positive nodes (x) and weights (y), the integrand
    // being even.
    var nodes = array<vec2<f32>, 8>(
        vec2<f32>(0.09501251, 0.18945061),
        vec2<f32>(0.28160355, 0.18260342),
        vec2<f32>(0.45801678, 0.16915652),
        vec2<f32>(0.61787624, 0.14959599),
        vec2<f32>(0.7554044, 0.12462897),
        vec2<f32>(0.8656312, 0.09515851),
        vec2<f32>(0.94457503, 0.06225352),
        vec2<f32>(0.9894009, 0.02715246),
    );
    var integral = 0.0;
    for (var i = 0; i < 8; i++) {
        let u = h * nodes[i].x;
        integral += nodes[i].y * specular_pow(ab * cos(2.0 * u) - l_t * v_t, n) * cos(u);
    }
    let half = sqrt((1.0 + cos_alpha) * 0.5);
    return vec2<f32>(diffuse, half * h * integral);
}
