//! Scene lights. LineAO attenuates occlusion where a light reaches the surface (Eq. 14–15) and the
//! line renderer adds the illuminated-lines specular with the same lights (paper §3.3).
//!
//! # Illuminated lines
//!
//! A line has no normal: every unit vector N ⟂ T is one. Zöckler et al. (1996) light it with the
//! brightest of them (the *maximum principle*): for unit L and V (toward the light and the eye),
//! with l_t = L·T and v_t = V·T, the best reflection is R·V = √(1−l_t²)·√(1−v_t²) − l_t·v_t.
//! That specular is what the paper adds on top of LineAO (§3.3, [`LineShading::Specular`]).
//!
//! Mallo et al. (2005, the paper's reference 13) treat the line as a cylinder too thin to resolve and
//! average the lighting over its visible half, each normal weighted by the width it covers on
//! screen (N·V⊥). With N(θ) around T, L⊥ and V⊥ the parts of L and V perpendicular to T and α the
//! angle between them, N·L = |L⊥| cos(θ − α) and the weight cos θ over θ ∈ [−π/2, π/2] give
//!
//! - diffuse: avg(max(N·L, 0)) = |L⊥| · (sin α + (π − α) cos α) / 4 (exact);
//! - specular: R·V = |L⊥||V⊥| cos(2θ − α) − l_t v_t =: g peaks at the bisector θ* = α/2 with
//!   Zöckler's value g*. Where N is both visible and lit, u = θ − θ* spans [−c, c] with
//!   c = (π − α)/2, and the weight cos(u + α/2) splits into an even and an odd part; g is even, so
//!   avg(g^n) = cos(α/2)/2 · ∫_{−c}^{c} g₊(u)^n cos u du. Mallo et al. tabulate such integrals;
//!   here 16-point Gauss–Legendre (8 evaluations by symmetry) over u ∈ ±min(c, u₀, 5σ), where g
//!   falls to 0 at u₀ (beyond it the integrand is 0 and has a kink there) and
//!   σ = √(g* / (4 n |L⊥||V⊥|)) is the width of the highlight by Laplace's method, so narrow
//!   highlights get all the nodes. Within 2e-5 of 20 000-point quadrature at shininess 8 and 32
//!   (`tests/lines.rs`; 8 points were 1 % off where the highlight is broad).
//!
//! [`LineShading::CylinderAveraged`] colors a line base · (1 − kd + kd · Σ I · diffuse) — the
//! same form as the Phong tubes — and adds Σ I · ks · specular.

use crate::named::Named;
use glam::Vec3;

/// At most this many lights reach the shaders.
pub const MAX_LIGHTS: usize = 4;

/// A directional light in view space.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Light {
    /// Direction toward the light, view space (normalized when uploaded).
    pub dir: Vec3,
    /// Intensity I.
    pub intensity: f32,
}

/// Lights and the Blinn-Phong material of Eq. 14 (and of the illuminated-lines specular).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Lighting {
    /// Up to [`MAX_LIGHTS`] lights; more are an error when the chain is prepared.
    pub lights: Vec<Light>,
    /// Diffuse coefficient kd, default 0.3.
    pub kd: f32,
    /// Specular coefficient ks, default 0.4.
    pub ks: f32,
    /// Shininess α, default 32.
    pub shininess: f32,
    /// How lines are lit (tubes and surfaces are Phong-shaded). Default
    /// [`LineShading::Specular`], the paper's combination.
    pub line_shading: LineShading,
}

impl Default for Lighting {
    /// docs/reference.md: one light toward normalize(−0.4, 0.6, 0.7), I = 1, kd 0.3, ks 0.4, α 32.
    fn default() -> Self {
        Lighting {
            lights: vec![Light { dir: Vec3::new(-0.4, 0.6, 0.7).normalize(), intensity: 1.0 }],
            kd: 0.3,
            ks: 0.4,
            shininess: 32.0,
            line_shading: LineShading::Specular,
        }
    }
}

/// How the line renderer lights lines (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineShading {
    /// The paper's combination (§3.3): the color as it is (LineAO stands for the ambient and
    /// diffuse light) plus the illuminated-lines specular of the maximum principle.
    #[default]
    Specular,
    /// Illuminated lines revisited (Mallo et al. 2005): diffuse and specular averaged over the
    /// visible half of an infinitesimal cylinder around the line.
    CylinderAveraged,
}

impl LineShading {
    /// The CLI and `params.json` name: `specular` or `cylinder`.
    pub fn name(self) -> &'static str {
        match self {
            LineShading::Specular => "specular",
            LineShading::CylinderAveraged => "cylinder",
        }
    }
}

/// The lighting of a line with unit tangent `t` seen from unit direction `v` (toward the eye)
/// by one light toward unit `l`, shininess `n`: (diffuse, specular) as [`LineShading`] computes
/// them, before intensities and kd/ks (`Specular`: diffuse 0, Zöckler's specular).
pub fn illuminated_line(shading: LineShading, l: Vec3, v: Vec3, t: Vec3, n: f32) -> (f32, f32) {
    let (l_t, v_t) = (l.dot(t), v.dot(t));
    let peak = (1.0 - l_t * l_t).max(0.0).sqrt() * (1.0 - v_t * v_t).max(0.0).sqrt() - l_t * v_t;
    let powered = if peak > 0.0 { peak.powf(n) } else { 0.0 };
    if shading == LineShading::Specular {
        return (0.0, powered);
    }
    let (l_perp, v_perp) = (l - l_t * t, v - v_t * t);
    let (a, b) = (l_perp.length(), v_perp.length());
    // Viewed end-on (or lit along the line) the angle between them is undefined: take 90°.
    let cos_alpha = if a * b > 1e-8 { (l_perp.dot(v_perp) / (a * b)).clamp(-1.0, 1.0) } else { 0.0 };
    let alpha = cos_alpha.acos();
    let pi = std::f32::consts::PI;
    let diffuse = 0.25 * a * ((1.0 - cos_alpha * cos_alpha).sqrt() + (pi - alpha) * cos_alpha);
    let (ab, k) = (a * b, l_t * v_t);
    let c = 0.5 * (pi - alpha);
    // Up to where g reaches 0 (the integrand's kink), at most 5 σ.
    let h = if ab > 1e-12 {
        let root = 0.5 * (k / ab).clamp(-1.0, 1.0).acos();
        c.min(root).min(5.0 * (peak.max(0.0) / (4.0 * n * ab)).sqrt())
    } else {
        c
    };
    let mut integral = 0.0;
    for (x, w) in GAUSS_LEGENDRE_16 {
        let u = h * x;
        let g = ab * (2.0 * u).cos() - k;
        integral += w * if g > 0.0 { g.powf(n) } else { 0.0 } * u.cos();
    }
    let half = ((1.0 + cos_alpha) * 0.5).sqrt();
    (diffuse, half * 0.5 * 2.0 * h * integral)
}

/// The positive nodes of 16-point Gauss–Legendre quadrature on [−1, 1] and their weights.
const GAUSS_LEGENDRE_16: [(f32, f32); 8] = [
    (0.095_012_51, 0.189_450_6),
    (0.281_603_55, 0.182_603_42),
    (0.458_016_78, 0.169_156_52),
    (0.617_876_24, 0.149_595_99),
    (0.755_404_4, 0.124_628_97),
    (0.865_631_2, 0.095_158_51),
    (0.944_575, 0.062_253_52),
    (0.989_400_9, 0.027_152_46),
];

/// Keep in sync with `shaders/shared/lighting.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightingUniform {
    /// Each light: its view-space direction toward the light (xyz) and intensity (w).
    pub lights: [[f32; 4]; MAX_LIGHTS],
    /// The lights in use.
    pub count: u32,
    /// Diffuse coefficient kd.
    pub kd: f32,
    /// Specular coefficient ks.
    pub ks: f32,
    /// Specular exponent α.
    pub shininess: f32,
    /// 0: [`LineShading::Specular`], 1: [`LineShading::CylinderAveraged`].
    pub line_shading: u32,
    /// Padding to WGSL's 16-byte alignment.
    pub _pad: [u32; 3],
}

impl Lighting {
    /// Light directions normalized, as the shaders see them.
    pub fn normalized(&self) -> Vec<Light> {
        self.lights.iter().map(|l| Light { dir: l.dir.normalize_or_zero(), intensity: l.intensity }).collect()
    }

    /// The uniform the shaders read.
    pub fn uniform(&self) -> LightingUniform {
        let mut lights = [[0.0; 4]; MAX_LIGHTS];
        let normalized = self.normalized();
        for (slot, light) in lights.iter_mut().zip(&normalized) {
            *slot = [light.dir.x, light.dir.y, light.dir.z, light.intensity];
        }
        LightingUniform {
            lights,
            count: normalized.len().min(MAX_LIGHTS) as u32,
            kd: self.kd,
            ks: self.ks,
            shininess: self.shininess,
            line_shading: self.line_shading as u32,
            _pad: [0; 3],
        }
    }
}

/// What of a [`Lighting`] a pipeline is compiled for (`LIGHTS`, `SHININESS_WHOLE` and
/// `LINE_SHADING` in `shaders/shared/lighting.wgsl`): the number of lights, a whole shininess and
/// how lines are lit, as constants, so that a CPU rasterizer runs straight code where a uniform
/// would have it run a loop of a uniform count and both sides of a branch for every lane. On
/// lavapipe (`lineao bench`, 1 M vertices) a frame's lines took 1.65× and tubes 1.32× as long
/// with these read from the uniform; LineAO 3× with its light loop. A pipeline made for
/// [`LightingShape::ANY`] takes every lighting from the uniform.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightingShape {
    /// The number of lights; `None`: the uniform's.
    pub lights: Option<u32>,
    /// The shininess where it is a whole number in 1..512 ([`whole_exponent`]); 0: `pow` with
    /// the uniform's.
    pub shininess_whole: u32,
    /// How lines are lit; `None`: the uniform's.
    pub line_shading: Option<LineShading>,
}

impl LightingShape {
    /// Every lighting, read from the uniform.
    pub const ANY: LightingShape = LightingShape { lights: None, shininess_whole: 0, line_shading: None };

    /// Exactly `lighting`'s shape.
    pub fn of(lighting: &Lighting) -> LightingShape {
        LightingShape {
            lights: Some(lighting.lights.len().min(MAX_LIGHTS) as u32),
            shininess_whole: whole_exponent(lighting.shininess),
            line_shading: Some(lighting.line_shading),
        }
    }

    /// Whether a pipeline of this shape draws `lighting` as it is.
    pub fn fits(&self, lighting: &Lighting) -> bool {
        let exact = LightingShape::of(lighting);
        self.lights.is_none_or(|n| Some(n) == exact.lights)
            && (self.shininess_whole == 0 || self.shininess_whole == exact.shininess_whole)
            && self.line_shading.is_none_or(|s| Some(s) == exact.line_shading)
    }

    /// The shaders' `override` constants.
    pub fn constants(&self) -> [(&'static str, f64); 3] {
        const ANY: f64 = u32::MAX as f64;
        [
            ("LIGHTS", self.lights.map_or(ANY, f64::from)),
            ("SHININESS_WHOLE", f64::from(self.shininess_whole)),
            ("LINE_SHADING", self.line_shading.map_or(ANY, |s| f64::from(s as u32))),
        ]
    }
}

/// `alpha` when it is a whole number in 1..512, which the shader raises by squaring (a pipeline
/// constant, `SHININESS_WHOLE`), else 0 (it calls `pow`).
pub fn whole_exponent(alpha: f32) -> u32 {
    if alpha.fract() == 0.0 && (1.0..512.0).contains(&alpha) { alpha as u32 } else { 0 }
}

/// max(x, 0)^n for a whole 1 ≤ n < 512 by squaring, multiplied in the shader's order
/// (`whole_pow` in `shaders/shared/lighting.wgsl`).
pub fn whole_pow(x: f32, n: u32) -> f32 {
    let (mut result, mut power) = (1.0f32, x.max(0.0));
    for bit in 0..9 {
        if (n >> bit) & 1 != 0 {
            result *= power;
        }
        power *= power;
    }
    result
}

crate::named::named!(LineShading {
    Specular => "Zöckler's maximum-principle specular added to the AO-darkened color (the paper's §3.3)",
    CylinderAveraged => "Mallo et al.'s cylinder-averaged diffuse and specular",
});

#[cfg(test)]
#[test]
fn uniform_matches_its_wgsl_struct() {
    crate::shader::assert_wgsl_layout!(
        LightingUniform,
        "shared/lighting.wgsl",
        "Lighting",
        [lights, count, kd, ks, shininess, line_shading]
    );
}
