//! The GPU ray tracer's settings: rays per frame, the cap, the reach, and the denoiser.

use crate::method::setting::{About, Kind, Setting, Unit, Value};

/// The ray tracer's settings as the front ends show them (docs/reference.md's flags, which the CPU
/// truth of `lineao score` and `render --cpu` reads too).
pub(crate) const SETTINGS: &[Setting<RayTracedSettings>] = &[
    Setting {
        about: About {
            flag: "rays",
            label: "rays per pixel",
            help: "Ray-traced AO: rays per geometry pixel, after which the picture is complete. 256 is LineVis's reference count: a standard error of at most 0.03 per pixel",
            kind: Kind::Count { min: 1, max: 1 << 20 },
            default: Some("256; the viewer's 1024"),
            ..About::BASE
        },
        get: |s, _| Value::Count(s.max_rays),
        set: |s, v| {
            s.max_rays = v.as_u32();
            s.rays_per_frame = s.rays_per_frame.min(s.max_rays);
        },
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "rays-per-frame",
            label: "rays per frame",
            help: "Ray-traced AO: rays per pixel each frame adds; fewer keep a slow GPU responsive",
            kind: Kind::Count { min: 1, max: 1024 },
            default: Some("render: the rays, at most 64; the viewer's 4"),
            ..About::BASE
        },
        get: |s, _| Value::Count(s.rays_per_frame),
        set: |s, v| s.rays_per_frame = v.as_u32(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "ao-distance",
            label: "reach",
            help: "Ray-traced AO: how far a ray looks for an occluder (the truth's R). 2 is the reach VO and SSAO sample by default and that of LineAO's widest hemisphere (r0 + 2 z(P) px); 20% is LineVis's default reach and score's bundle-scale truth",
            unit: Unit::WorldUnits,
            kind: Kind::Reach { slider: [0.1, 20.0] },
            ..About::BASE
        },
        get: |s, _| s.distance_share.map_or(Value::Number(s.distance_world), Value::Share),
        set: |s, v| match v {
            Value::Share(share) => s.distance_share = Some(share),
            v => (s.distance_world, s.distance_share) = (v.as_f32(), None),
        },
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "ao-falloff",
            label: "falloff",
            help: "Ray-traced AO: binary (none) or obscurance with a linear falloff (linear)",
            kind: Kind::Choice(&["none", "linear"]),
            ..About::BASE
        },
        get: |s, _| Value::Choice(s.falloff.name()),
        set: |s, v| s.falloff = v.named(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "ray-seed",
            label: "seed",
            help: "Ray-traced AO: seed of the per-pixel scrambled ray sequence",
            kind: Kind::Count { min: 0, max: u32::MAX },
            ..About::BASE
        },
        get: |s, _| Value::Count(s.seed),
        set: |s, v| s.seed = v.as_u32(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "denoise",
            label: "denoise (edge-aware)",
            help: "Ray-traced AO on the GPU: the edge-aware denoiser after the rays (same line or surface, a window narrowing as 1/√rays), for few rays",
            kind: Kind::Switch { given: true },
            ..About::BASE
        },
        get: |s, _| Value::Switch(s.denoise.is_some()),
        set: |s, v| s.denoise = v.is_on().then(|| s.denoise.clone().unwrap_or_default()),
        ..Setting::BASE
    },
];

/// The ray-traced method on the GPU ([`crate::method::raytraced`]): rays per frame while the
/// view rests, accumulated up to a cap, as the CPU truth traces them.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RayTracedSettings {
    /// Rays per geometry pixel each frame, ≥ 1. Default 4 (LineVis's).
    pub rays_per_frame: u32,
    /// Rays per pixel after which the frame is converged and nothing more is traced, ≥ 1.
    /// Default 256 (LineVis's reference count).
    pub max_rays: u32,
    /// The rays' reach R in world units, > 0. Default 2 (the truth's).
    pub distance_world: f32,
    /// Where set, the reach is this share in (0, 1] of the longest side of the ray scene's
    /// axis-aligned bounds instead ([`RayTracedSettings::resolve`]; LineVis's 0.2).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub distance_share: Option<f32>,
    /// Binary AO or obscurance with a linear falloff.
    pub falloff: crate::truth::Falloff,
    /// Seed of the per-pixel scramble (the CPU truth's `seed`).
    pub seed: u32,
    /// The edge-aware denoiser ([`crate::method::raytraced::denoise`]), or none. Default none: the
    /// picture as traced (what `lineao score` scores).
    pub denoise: Option<RayDenoiseSettings>,
}

/// The ray tracer's edge-aware denoiser: each pixel's mean averaged with its neighbours' on the
/// same surface, in a window whose Gaussian narrows as 1/√rays, so it smooths the first frames
/// and fades out as the picture converges.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RayDenoiseSettings {
    /// Pixels on each side of the window, 1..=8. Default 3.
    pub radius_px: u32,
    /// σ of the spatial Gaussian at 4 rays per pixel, in pixels, > 0 (σ = sigma_px · √(4/rays);
    /// below a quarter pixel the window is the pixel alone). Default 1.5.
    pub sigma_px: f32,
    /// Neighbours count with max(n·n', 0)^normal_power, ≥ 0. Default 32.
    pub normal_power: f32,
    /// Lines and tubes: neighbours whose own segments are at most this many vertices apart along
    /// the polyline, ≥ 0. Default 2.
    pub reach_vertices: u32,
    /// Meshes: neighbours whose depth differs by at most this share of the pixel's, in (0, 1].
    /// Default 0.02.
    pub depth_tolerance: f32,
}

impl Default for RayDenoiseSettings {
    fn default() -> Self {
        RayDenoiseSettings { radius_px: 3, sigma_px: 1.5, normal_power: 32.0, reach_vertices: 2, depth_tolerance: 0.02 }
    }
}

impl RayDenoiseSettings {
    /// 1/(2σ²) of the spatial Gaussian after `rays` rays per pixel, or 0 where σ is below a
    /// quarter pixel (the pixel alone). Tubes take half the σ: several pixels wide, their
    /// occlusion changes across their width, which lines a pixel or two wide do not show
    /// (measured against the truth in docs/ground-truth.md).
    pub fn spatial(&self, rays: u32, tubes: bool) -> f32 {
        let sigma = self.sigma_px * (4.0 / rays.max(1) as f32).sqrt() * if tubes { 0.5 } else { 1.0 };
        if sigma < 0.25 { 0.0 } else { 1.0 / (2.0 * sigma * sigma) }
    }

    /// Its ranges, as [`crate::Error::OutOfRange`].
    pub fn validate(&self) -> Result<(), crate::Error> {
        let ok = (1..=8).contains(&self.radius_px)
            && self.sigma_px.is_finite()
            && self.sigma_px > 0.0
            && self.normal_power.is_finite()
            && self.normal_power >= 0.0
            && self.depth_tolerance > 0.0
            && self.depth_tolerance <= 1.0;
        if ok {
            return Ok(());
        }
        let expected = "a radius of 1..=8 px, σ > 0, normal power ≥ 0 and depth tolerance in (0, 1]";
        Err(crate::Error::out_of_range("denoise", format!("{self:?}"), expected))
    }
}

impl Default for RayTracedSettings {
    fn default() -> Self {
        let truth = crate::truth::TruthSettings::default();
        RayTracedSettings {
            rays_per_frame: 4,
            max_rays: 256,
            distance_world: truth.distance_world,
            distance_share: None,
            falloff: truth.falloff,
            seed: truth.seed,
            denoise: None,
        }
    }
}

impl RayTracedSettings {
    /// The reach in world units in a scene whose bounds' longest side is `longest_side`.
    pub fn reach(&self, longest_side: f32) -> f32 {
        self.distance_share.map_or(self.distance_world, |share| share * longest_side)
    }

    /// The reach as world units (the share of `longest_side` where one is set, which is then
    /// cleared): what a front end that knows its scene's bounds does once.
    pub fn resolve(&mut self, longest_side: f32) {
        self.distance_world = self.reach(longest_side);
        self.distance_share = None;
    }

    /// The CPU truth's settings tracing the same rays as `rays` rays per pixel of these.
    pub fn truth(&self, rays: u32) -> crate::truth::TruthSettings {
        crate::truth::TruthSettings {
            rays,
            distance_world: self.distance_world,
            falloff: self.falloff,
            seed: self.seed,
            vo: None,
            second: None,
            threads: 0,
        }
    }

    /// Its ranges, as [`crate::Error::OutOfRange`].
    pub fn validate(&self) -> Result<(), crate::Error> {
        if self.rays_per_frame == 0 {
            return Err(crate::Error::out_of_range("rays-per-frame", self.rays_per_frame, "≥ 1"));
        }
        if self.max_rays == 0 {
            return Err(crate::Error::out_of_range("rays", self.max_rays, "≥ 1"));
        }
        if let Some(denoise) = &self.denoise {
            denoise.validate()?;
        }
        if let Some(share) = self.distance_share.filter(|s| !(*s > 0.0 && *s <= 1.0)) {
            return Err(crate::Error::out_of_range("ao-distance", share, "a share of the scene in (0, 1]"));
        }
        self.truth(1).validate()
    }
}
