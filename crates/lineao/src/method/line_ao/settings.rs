//! LineAO's settings: the paper's parameters (Eq. 7–15), the authors' variant, and where the
//! outer hemispheres are evaluated.

use crate::method::setting::{About, Context, Kind, Setting, Unit, Value};
use crate::named::{Named, named};
use crate::preset::Preset;

/// LineAO's settings as the front ends show them (docs/reference.md's flags). The variant first: a
/// preset's values depend on it.
pub(crate) const SETTINGS: &[Setting<LineAoSettings>] = &[
    Setting {
        about: About {
            flag: "variant",
            label: "variant",
            help: "LineAO: the paper's equations (paper) or what the authors' OpenWalnut shader does (reference)",
            kind: Kind::Choice(&["paper", "reference"]),
            ..About::BASE
        },
        get: |s, _| Value::Choice(s.variant.name()),
        set: |s, v| s.variant = v.named(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "outer",
            label: "outer hemispheres",
            help: "LineAO (variant paper): hemispheres j ≥ 1 at every pixel (full) or at their pyramid level's resolution, upsampled depth-aware (level: faster)",
            kind: Kind::Choice(&["full", "level"]),
            ..About::BASE
        },
        applies: |s| s.variant == LineAoVariant::Paper,
        get: |s, _| Value::Choice(s.outer.name()),
        set: |s, v| s.outer = v.named(),
    },
    Setting {
        about: About {
            flag: "s-r",
            label: "s_r hemispheres",
            help: "LineAO s_r: hemispheres and pyramid levels",
            kind: Kind::Count { min: 1, max: crate::MAX_LEVELS },
            default: Some("the preset's; paper 3"),
            ..About::BASE
        },
        applies: |s| s.variant == LineAoVariant::Paper,
        get: |s, _| Value::Count(s.s_r),
        set: |s, v| s.s_r = v.as_u32(),
    },
    Setting {
        about: About {
            flag: "s-h",
            label: "s_h samples",
            help: "LineAO s_h: samples on the first hemisphere",
            kind: Kind::Count { min: 1, max: 256 },
            ..About::BASE
        },
        get: |s, _| Value::Count(s.s_h),
        set: |s, v| s.s_h = v.as_u32(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "r0",
            label: "r0",
            help: "LineAO r0, the first hemisphere's radius",
            unit: Unit::Px,
            kind: Kind::Above { min: 0.0, open: false, slider: [0.5, 16.0], log: false },
            default: Some("the preset's × the line width; paper 1.5 ×"),
            ..About::BASE
        },
        applies: |s| s.variant == LineAoVariant::Paper,
        get: |s, context| Value::Number(s.r0_px(context)),
        set: |s, v| s.r0_px = Some(v.as_f32()),
    },
    Setting {
        about: About {
            flag: "reference-radius",
            label: "base radius",
            help: "LineAO (variant reference): the base radius at the home zoom (the authors' u_lineAORadius)",
            unit: Unit::Px,
            kind: Kind::Above { min: 0.0, open: false, slider: [0.5, 8.0], log: false },
            default: Some("the preset's; paper 2"),
            ..About::BASE
        },
        applies: |s| s.variant == LineAoVariant::Reference,
        get: |s, _| Value::Number(s.reference_radius_px),
        set: |s, v| s.reference_radius_px = v.as_f32(),
    },
    Setting {
        about: About {
            flag: "delta0",
            label: "δ0",
            help: "LineAO δ0: occluders nearer than this in normalized depth count fully; below δ scale · (1/s_r)²",
            kind: Kind::Number { min: 0.0, max: 1.0, open: false, log: true },
            ..About::BASE
        },
        get: |s, _| Value::Number(s.delta0),
        set: |s, v| s.delta0 = v.as_f32(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "delta-scale",
            label: "δ scale",
            help: "LineAO: scale of the falloff δ(j) = scale · (1 − j/s_r)²; below 1 occluders far in front (in normalized depth) stop counting",
            kind: Kind::Number { min: 0.0, max: 1.0, open: true, log: true },
            default: Some("the preset's; paper 1"),
            ..About::BASE
        },
        get: |s, _| Value::Number(s.delta_scale),
        set: |s, v| s.delta_scale = v.as_f32(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "epsilon",
            label: "ε",
            help: "LineAO ε: occluded iff Δd > ε",
            kind: Kind::Above { min: 0.0, open: false, slider: [1e-8, 1e-3], log: true },
            ..About::BASE
        },
        get: |s, _| Value::Number(s.epsilon),
        set: |s, v| s.epsilon = v.as_f32(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "no-light-attenuation",
            label: "light attenuation g_light",
            help: "Disable LineAO's light attenuation (g_light = 1)",
            kind: Kind::Switch { given: false },
            ..About::BASE
        },
        get: |s, _| Value::Switch(s.light_attenuation),
        set: |s, v| s.light_attenuation = v.is_on(),
        ..Setting::BASE
    },
];

/// What a panel's control leaves valid: δ0 below the last hemisphere's δ, the full-resolution
/// outer hemispheres for the authors' variant.
pub(crate) fn conform(ao: &mut LineAoSettings) {
    let last_delta = ao.delta_scale / (ao.s_r * ao.s_r) as f32;
    ao.delta0 = ao.delta0.min(0.9 * last_delta);
    if ao.variant == LineAoVariant::Reference {
        ao.outer = LineAoOuter::Full;
    }
}

/// Which LineAO: the paper's equations, or what the authors' own code does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineAoVariant {
    /// Eq. 4–15 with docs/reference.md's conventions.
    #[default]
    Paper,
    /// The authors' OpenWalnut shader (DESIGN.md): no pyramid, radii growing 1.5, 4, 7.5 times a
    /// depth-scaled base radius, s_h samples per hemisphere skipping off-screen ones, the
    /// `1.5 − …` light weight, ao = max(0, Σ occ_l / s_r). See [`crate::method::line_ao`].
    Reference,
}

named!(LineAoVariant {
    Paper => "The paper's equations with docs/reference.md's conventions",
    Reference => "What the authors' OpenWalnut shader does (no pyramid, growing radii, `1.5 − …` weights)",
});
named!(LineAoOuter {
    Full => "Hemispheres j ≥ 1 at every pixel, as the paper does",
    Level => "Hemispheres j ≥ 1 at level j's resolution, upsampled depth-aware",
});

impl LineAoVariant {
    /// The name used on the command line and in `params.json`.
    pub fn name(self) -> &'static str {
        match self {
            LineAoVariant::Paper => "paper",
            LineAoVariant::Reference => "reference",
        }
    }
}

/// The LineAO parameters of Eq. 7–15 (docs/reference.md "LineAO").
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct LineAoSettings {
    /// `paper` (the paper's equations) or `reference` (the authors' shader).
    pub variant: LineAoVariant,
    /// s_r: number of hemispheres and pyramid levels, 1..=5; the paper uses 3 (and needs > 1
    /// for δ(l) to fall off).
    pub s_r: u32,
    /// s_h: samples on the first hemisphere, 1..=256; hemisphere j takes ⌈s_h/(j+1)⌉. Default 32.
    pub s_h: u32,
    /// r0 in pixels for lines; `None` = `r0_per_width` × the line width.
    pub r0_px: Option<f32>,
    /// r0 for lines as a multiple of the line width where `r0_px` is `None`, ≥ 0: 1.5 in the
    /// paper (§3.2.3), 4.5 in the default preset (`legible`).
    pub r0_per_width: f32,
    /// δ0, the depth difference below which an occluder counts fully. Default 1e-4.
    pub delta0: f32,
    /// Scale of the falloff δ(j) = delta_scale · (1 − j/s_r)² (Eq. 11), in (0, 1]: the depth
    /// difference (normalized depth) beyond which hemisphere j's occluders no longer count. The
    /// paper's 1 lets anything in front count, however far; smaller values keep occlusion local
    /// in depth. Default 1 (paper).
    pub delta_scale: f32,
    /// ε: occluded iff Δd > ε. Default 1e-6 (docs/reference.md departs from Eq. 8's Δd ≥ 0).
    pub epsilon: f32,
    /// Light attenuation g_light of Eq. 15; off means g_light = 1.
    pub light_attenuation: bool,
    /// Seed of the R1/R2 noise (docs/reference.md "Noise"). Default 1.
    pub noise_seed: u32,
    /// Variant `reference`: the base radius in pixels at the home zoom (the authors'
    /// `u_lineAORadius`). Default 2.
    pub reference_radius_px: f32,
    /// Variant `paper`: hemispheres j ≥ 1 at full resolution or at their level's (docs/reference.md).
    pub outer: LineAoOuter,
}

/// Where LineAO evaluates its outer hemispheres (j ≥ 1; docs/reference.md `outer`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LineAoOuter {
    /// At every pixel, as the paper does.
    #[default]
    Full,
    /// At every texel of pyramid level j (a quarter of the pixels for j = 1, a sixteenth for
    /// j = 2), then upsampled depth-aware: the wide hemispheres read blurred levels anyway, so
    /// their AO varies slowly and costs far less this way.
    Level,
}

impl LineAoOuter {
    /// The `params.json` and CLI name: `full` or `level`.
    pub fn name(self) -> &'static str {
        match self {
            LineAoOuter::Full => "full",
            LineAoOuter::Level => "level",
        }
    }
}

impl Default for LineAoSettings {
    fn default() -> Self {
        LineAoSettings {
            s_r: 3,
            s_h: 32,
            r0_px: None,
            r0_per_width: 1.5,
            delta0: 1e-4,
            delta_scale: 1.0,
            epsilon: 1e-6,
            light_attenuation: true,
            noise_seed: 1,
            variant: LineAoVariant::Paper,
            reference_radius_px: 2.0,
            outer: LineAoOuter::Full,
        }
    }
}

/// LineAO's settings in a chain's: its own, and r0 as the line width or the tubes make it.
pub(crate) fn validate(settings: &LineAoSettings, context: &Context) -> Result<(), crate::Error> {
    settings.validate()?;
    let r0 = settings.r0_px(context);
    if !(r0.is_finite() && r0 >= 0.0) {
        return Err(crate::Error::out_of_range("r0", r0, "a finite number of pixels ≥ 0"));
    }
    Ok(())
}

impl LineAoSettings {
    /// r0's constant part in pixels: the explicit value, or `r0_per_width` × the line width
    /// (tubes: 0).
    pub fn r0_px(&self, context: &Context) -> f32 {
        let default = if context.tubes { 0.0 } else { self.r0_per_width * context.line_width_px };
        self.r0_px.unwrap_or(default)
    }

    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        if !(1..=crate::MAX_LEVELS).contains(&self.s_r) {
            return Err(crate::Error::out_of_range("s-r", self.s_r, &format!("1..={}", crate::MAX_LEVELS)));
        }
        if !(1..=256).contains(&self.s_h) {
            return Err(crate::Error::out_of_range("s-h", self.s_h, "1..=256"));
        }
        if !(self.r0_per_width.is_finite() && self.r0_per_width >= 0.0) {
            return Err(crate::Error::out_of_range("r0", self.r0_per_width, "≥ 0 line widths"));
        }
        if !(self.delta_scale.is_finite() && self.delta_scale > 0.0 && self.delta_scale <= 1.0) {
            return Err(crate::Error::out_of_range("delta-scale", self.delta_scale, "(0, 1]"));
        }
        let last_delta = self.delta_scale * (1.0 / self.s_r as f32).powi(2);
        if !(self.delta0.is_finite() && self.delta0 >= 0.0 && self.delta0 < last_delta) {
            return Err(crate::Error::out_of_range(
                "delta0",
                self.delta0,
                &format!("[0, δ scale · (1/s_r)²) = [0, {last_delta})"),
            ));
        }
        if self.variant == LineAoVariant::Reference && self.outer == LineAoOuter::Level {
            let why = "outer = level applies to variant paper (reference reads level 0 only)";
            return Err(crate::Error::Conflict { setting: "outer", with: "variant", why });
        }
        if !(self.reference_radius_px.is_finite() && self.reference_radius_px >= 0.0) {
            return Err(crate::Error::out_of_range("reference-radius", self.reference_radius_px, "≥ 0 px"));
        }
        if !(self.epsilon.is_finite() && self.epsilon >= 0.0) {
            return Err(crate::Error::out_of_range("epsilon", self.epsilon, "≥ 0"));
        }
        Ok(())
    }
}

/// LineAO's first radius r0(P) = `px` + `per_zoom` · z(P) pixels: a constant for lines (1.5 ×
/// the line width), 1.5 · t_s · z(P) for tubes of width t_s zoom units (paper Eq. 16).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct R0 {
    /// The part in pixels.
    pub px: f32,
    /// The part per unit of zoom z(P).
    pub per_zoom: f32,
}

impl From<f32> for R0 {
    fn from(px: f32) -> R0 {
        R0 { px, per_zoom: 0.0 }
    }
}

/// LineAO's values in `preset` (`lineao score --fit`, docs/ground-truth.md): s_r, δ scale, r0
/// (lines; tubes keep Eq. 16's) and the authors' base radius; the strength it is shown with.
pub(crate) fn preset(preset: Preset, ao: &mut LineAoSettings, _: &Context) -> f32 {
    let paper = LineAoSettings::default();
    (ao.s_r, ao.delta_scale, ao.r0_per_width, ao.reference_radius_px) =
        (paper.s_r, paper.delta_scale, paper.r0_per_width, paper.reference_radius_px);
    // r0 follows the line width.
    ao.r0_px = None;
    match (preset, ao.variant) {
        (Preset::Paper, _) => 1.0,
        // The most legible settings that keep every view readable (`lineao score --fit --width
        // 640 --height 512 --fit-views 2 --rays 32`): two hemispheres, the first reaching past a
        // line's own width to its neighbours (r0 4.5 × the width), the paper's δ (occluders far
        // in front count: depth order is the question); held-out legibility +0.371 (the papers'
        // values +0.29 on the real files), never near-black. The authors' variant is more
        // legible (+0.497) but costs 2.55 × Crytek SSAO's frame on lavapipe, so it is not what
        // `lineao` renders by default.
        (Preset::Legible, LineAoVariant::Paper) => {
            (ao.s_r, ao.r0_per_width) = (2, 4.5);
            0.6
        }
        (Preset::Legible, LineAoVariant::Reference) => 0.6,
        // Two hemispheres with δ a tenth of the paper's: the third hemisphere and occluders far
        // in front (in depth) darken dense and sparse data alike, where the truth tells them
        // apart; with them LineAO's mean stays within 0.1 of the truth's on every real
        // tractogram (within 0.09), and its held-out RMSE is 0.204 (paper: 0.450).
        (Preset::Physical, LineAoVariant::Paper) => {
            (ao.s_r, ao.delta_scale) = (2, 0.1);
            0.58
        }
        (Preset::Physical, LineAoVariant::Reference) => {
            ao.reference_radius_px = 1.0;
            0.46
        }
        // A fourth hemisphere on a fourth level: twice the third's reach, for neighbours far
        // apart. The authors' variant has one radius, which the sparse look leaves alone.
        (Preset::Sparse, LineAoVariant::Paper) => {
            ao.s_r = 4;
            0.8
        }
        (Preset::Sparse, LineAoVariant::Reference) => 0.8,
    }
}
