//! Crytek SSAO's settings: the kernel, its radius and range check in world units.

use crate::method::setting::{About, Context, Kind, Role, Setting, Unit, Value};
use crate::named::{Named, named};
use crate::preset::Preset;

/// SSAO's settings as the front ends show them (docs/reference.md's flags).
pub(crate) const SETTINGS: &[Setting<SsaoSettings>] = &[
    Setting {
        about: About {
            flag: "ssao-kernel",
            label: "kernel",
            help: "SSAO: the kernel's points: Mittring's random kernel, denser near the centre (crytek), or the VO paper's generated point set (sphere)",
            kind: Kind::Choice(&["crytek", "sphere"]),
            ..About::BASE
        },
        get: |s, _| Value::Choice(s.kernel.name()),
        set: |s, v| s.kernel = v.named(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "ssao-samples",
            label: "samples",
            help: "SSAO: point samples in the sphere; the sphere kernel takes 8, 12, 16, 24 or 32",
            kind: Kind::Count { min: 8, max: 32 },
            role: Some(Role::Samples),
            ..About::BASE
        },
        get: |s, _| Value::Count(s.samples),
        set: |s, v| s.samples = v.as_u32(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "ssao-radius",
            help: "SSAO: sphere radius (the range check's too, unless --ssao-range gives it)",
            ..About::SPHERE_RADIUS
        },
        get: |s, _| Value::Number(s.radius_world),
        set: |s, v| (s.radius_world, s.range_world) = (v.as_f32(), v.as_f32()),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "ssao-range",
            label: "range check",
            help: "SSAO: a sample occludes only where the surface in front of it is nearer than this",
            unit: Unit::WorldUnits,
            kind: Kind::Above { min: 0.0, open: true, slider: [0.1, 20.0], log: true },
            default: Some("the radius"),
            ..About::BASE
        },
        get: |s, _| Value::Number(s.range_world),
        set: |s, v| s.range_world = v.as_f32(),
        ..Setting::BASE
    },
];

/// What a panel's control leaves valid: the sphere kernel's sample counts only (the nearest).
pub(crate) fn conform(ssao: &mut SsaoSettings) {
    if ssao.kernel == SsaoKernel::Sphere {
        let counts = crate::sample_sets::VO_SPHERE_SAMPLE_COUNTS;
        ssao.samples = counts.iter().copied().min_by_key(|&n| n.abs_diff(ssao.samples)).unwrap_or(16);
    }
}

named!(SsaoKernel {
    Crytek => "Mittring's random kernel, denser near the centre",
    Sphere => "The VO paper's generated point set (8, 12, 16, 24 or 32 samples)",
});

/// Crytek SSAO (`lineao::method::ssao`).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct SsaoSettings {
    /// Point samples in the sphere (8..=32).
    pub samples: u32,
    /// Radius of the sampling sphere in world units.
    pub radius_world: f32,
    /// Range check: a sample counts as occluded only when the visible surface is in front of it
    /// by less than this (world units), so far-away foreground does not darken the background.
    pub range_world: f32,
    /// Seed of the kernel and the 4 × 4 rotation tile.
    pub noise_seed: u32,
    /// Where the kernel's points come from.
    pub kernel: SsaoKernel,
}

impl Default for SsaoSettings {
    fn default() -> Self {
        SsaoSettings { samples: 16, radius_world: 2.0, range_world: 2.0, noise_seed: 1, kernel: SsaoKernel::Crytek }
    }
}

impl SsaoSettings {
    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        if !(8..=32).contains(&self.samples) {
            return Err(crate::Error::out_of_range("ssao-samples", self.samples, "8..=32"));
        }
        if self.kernel == SsaoKernel::Sphere && !crate::sample_sets::VO_SPHERE_SAMPLE_COUNTS.contains(&self.samples) {
            return Err(crate::Error::out_of_range(
                "ssao-samples",
                self.samples,
                &format!("one of {:?} with the sphere kernel", crate::sample_sets::VO_SPHERE_SAMPLE_COUNTS),
            ));
        }
        if !(self.radius_world.is_finite() && self.radius_world > 0.0) {
            return Err(crate::Error::out_of_range("ssao-radius", self.radius_world, "> 0 world units"));
        }
        if !(self.range_world.is_finite() && self.range_world > 0.0) {
            return Err(crate::Error::out_of_range("ssao-range", self.range_world, "> 0 world units"));
        }
        Ok(())
    }
}

impl SsaoSettings {
    /// The kernel's points in the unit ball (scaled by the radius in the pass).
    pub fn kernel_points(&self) -> Vec<[f32; 3]> {
        match self.kernel {
            SsaoKernel::Crytek => crate::noise::ssao_kernel(self.noise_seed, self.samples),
            SsaoKernel::Sphere => crate::sample_sets::vo_sphere_samples(self.samples).unwrap_or_default().to_vec(),
        }
    }
}

/// The SSAO kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SsaoKernel {
    /// Mittring's: random directions, lengths growing quadratically (denser near the centre).
    #[default]
    Crytek,
    /// The VO paper's point-sample set (§4.5): every point an equal share of the ball
    /// (`lineao::sample_sets::VO_SPHERE_SAMPLE_COUNTS` sizes only).
    Sphere,
}

impl SsaoKernel {
    /// The CLI and `params.json` name: `crytek` or `sphere`.
    pub fn name(self) -> &'static str {
        match self {
            SsaoKernel::Crytek => "crytek",
            SsaoKernel::Sphere => "sphere",
        }
    }
}

/// SSAO's sphere (radius and range, zoom units) in `preset` (docs/ground-truth.md); the strength
/// it is shown with.
pub(crate) fn preset(preset: Preset, ssao: &mut SsaoSettings, context: &Context) -> f32 {
    let (strength, radius) = match preset {
        Preset::Paper => (1.0, 2.0),
        Preset::Legible => (1.0, 8.0),
        Preset::Physical => (0.68, 3.0),
        Preset::Sparse => (0.8, 6.0),
    };
    ssao.radius_world = radius * context.zoom_unit;
    ssao.range_world = radius * context.zoom_unit;
    strength
}
