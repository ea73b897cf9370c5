//! Volumetric Obscurance's settings, shared by line and area sampling (`vo_area` builds on
//! `vo_line`): the sample sets, the radii, the normal clamp and the thickness.

use crate::method::setting::{About, Context, Kind, Role, Setting, Unit, Value};
use crate::named::{Named, named};
use crate::preset::Preset;
use crate::sample_sets::{VO_AREA_SAMPLE_COUNTS, VO_SAMPLE_COUNTS};

/// VO line's settings as the front ends show them (docs/reference.md's flags): its samples, and the
/// sphere that area sampling shares ([`AREA_SETTINGS`]).
pub(crate) const SETTINGS: &[Setting<VoSettings>] = &[SAMPLES, RADIUS, RADIUS2, COMBINE, NORMAL_CLAMP, THICKNESS];

/// VO area's: its samples and VO line's sphere (a setting two methods list is one flag).
pub(crate) const AREA_SETTINGS: &[Setting<VoSettings>] =
    &[AREA_SAMPLES, RADIUS, RADIUS2, COMBINE, NORMAL_CLAMP, THICKNESS];

const SAMPLES: Setting<VoSettings> = Setting {
    about: About {
        flag: "vo-samples",
        label: "line samples",
        help: "VO line sampling: line samples",
        kind: Kind::Counts(&VO_SAMPLE_COUNTS),
        role: Some(Role::Samples),
        ..About::BASE
    },
    get: |s, _| Value::Count(s.samples),
    set: |s, v| s.samples = v.as_u32(),
    ..Setting::BASE
};

const AREA_SAMPLES: Setting<VoSettings> = Setting {
    about: About {
        flag: "vo-area-samples",
        label: "area samples",
        help: "VO area sampling: area samples (1 or a line count)",
        kind: Kind::Counts(&VO_AREA_SAMPLE_COUNTS),
        role: Some(Role::Samples),
        ..About::BASE
    },
    get: |s, _| Value::Count(s.area_samples),
    set: |s, v| s.area_samples = v.as_u32(),
    ..Setting::BASE
};

const RADIUS: Setting<VoSettings> = Setting {
    about: About { flag: "vo-radius", help: "VO (line and area sampling): sphere radius", ..About::SPHERE_RADIUS },
    get: |s, _| Value::Number(s.radius_world),
    set: |s, v| s.radius_world = v.as_f32(),
    ..Setting::BASE
};

const RADIUS2: Setting<VoSettings> = Setting {
    about: About {
        flag: "radius2",
        label: "second radius",
        help: "VO: a second sphere radius, combined with the first (VO paper, Fig. 8); 0: none",
        unit: Unit::WorldUnits,
        kind: Kind::Above { min: 0.0, open: false, slider: [0.0, 20.0], log: false },
        default: Some("none"),
        ..About::BASE
    },
    get: |s, _| Value::Number(s.radius2_world.unwrap_or(0.0)),
    set: |s, v| s.radius2_world = Some(v.as_f32()).filter(|r| *r > 0.0),
    ..Setting::BASE
};

const COMBINE: Setting<VoSettings> = Setting {
    about: About {
        flag: "combine",
        label: "two radii combine",
        help: "VO with two radii: brightness multiplied (product) or the darker of the two (min)",
        kind: Kind::Choice(&["product", "min"]),
        requires: Some("radius2"),
        ..About::BASE
    },
    applies: |s| s.radius2_world.is_some(),
    get: |s, _| Value::Choice(s.combine.name()),
    set: |s, v| s.combine = v.named(),
};

const NORMAL_CLAMP: Setting<VoSettings> = Setting {
    about: About {
        flag: "no-normal-clamp",
        label: "normal clamp (half sphere)",
        help: "VO: no normal clamp (the whole sphere, not the half above the surface)",
        kind: Kind::Switch { given: false },
        ..About::BASE
    },
    get: |s, _| Value::Switch(s.normal_clamp),
    set: |s, v| s.normal_clamp = v.is_on(),
    ..Setting::BASE
};

const THICKNESS: Setting<VoSettings> = Setting {
    about: About {
        flag: "thickness",
        label: "thickness",
        help: "VO: thickness model, occupied only this far behind the visible surface; 0: off",
        unit: Unit::WorldUnits,
        kind: Kind::Above { min: 0.0, open: false, slider: [0.0, 10.0], log: false },
        ..About::BASE
    },
    get: |s, _| Value::Number(s.thickness_world),
    set: |s, v| s.thickness_world = v.as_f32(),
    ..Setting::BASE
};

named!(VoCombine {
    Product => "Brightness multiplies: 1 − (1 − ao_a)(1 − ao_b)",
    Min => "The darker of the two",
});

/// How two occlusions combine: VO at two radii (VO paper, Fig. 8), or object-space AO with the
/// screen-space method's ([`VolumeAoSettings`](crate::VolumeAoSettings)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum VoCombine {
    /// Brightness multiplies: ao = 1 − (1 − ao_small)(1 − ao_large).
    #[default]
    Product,
    /// The darker one: ao = max(ao_small, ao_large).
    Min,
}

impl VoCombine {
    /// The name used on the command line and in `params.json`.
    pub fn name(self) -> &'static str {
        match self {
            VoCombine::Product => "product",
            VoCombine::Min => "min",
        }
    }
}

/// Volumetric Obscurance (`lineao::method::vo_line`, `lineao::method::vo_area`).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct VoSettings {
    /// Line samples: one of `lineao::sample_sets::VO_SAMPLE_COUNTS` (5, 7, 9, 12, 13, 16).
    pub samples: u32,
    /// Area samples: one of `lineao::sample_sets::VO_AREA_SAMPLE_COUNTS` (1 or a line count).
    /// Default 1.
    pub area_samples: u32,
    /// Radius of the sphere in world units.
    pub radius_world: f32,
    /// A second radius: VO is evaluated at both and combined by `combine`, so fine features
    /// (the small one) and wide contact shadows (the large one) both show.
    pub radius2_world: Option<f32>,
    /// How two radii combine.
    pub combine: VoCombine,
    /// Restrict the sphere to the half above the surface's tangent plane (§4.4).
    pub normal_clamp: bool,
    /// Thickness model (§4.3): occupied only this far behind the visible surface, world units;
    /// 0 = off (occupied all the way back).
    pub thickness_world: f32,
    /// Seed of the 4 × 4 tile of 2D reflection directions.
    pub noise_seed: u32,
}

impl VoSettings {
    /// The larger of the radii: what the guard band must cover.
    pub fn max_radius_world(&self) -> f32 {
        self.radius2_world.map_or(self.radius_world, |r| r.max(self.radius_world))
    }
}

impl Default for VoSettings {
    fn default() -> Self {
        VoSettings {
            samples: 9,
            area_samples: 1,
            radius_world: 2.0,
            radius2_world: None,
            combine: VoCombine::Product,
            normal_clamp: true,
            thickness_world: 0.0,
            noise_seed: 1,
        }
    }
}

impl VoSettings {
    /// Checks every range documented above.
    pub fn validate(&self) -> Result<(), crate::Error> {
        if !crate::sample_sets::VO_SAMPLE_COUNTS.contains(&self.samples) {
            return Err(crate::Error::out_of_range(
                "vo-samples",
                self.samples,
                &format!("one of {:?}", crate::sample_sets::VO_SAMPLE_COUNTS),
            ));
        }
        if !crate::sample_sets::VO_AREA_SAMPLE_COUNTS.contains(&self.area_samples) {
            return Err(crate::Error::out_of_range(
                "vo-area-samples",
                self.area_samples,
                &format!("one of {:?}", crate::sample_sets::VO_AREA_SAMPLE_COUNTS),
            ));
        }
        for radius in std::iter::once(self.radius_world).chain(self.radius2_world) {
            if !(radius.is_finite() && radius > 0.0) {
                return Err(crate::Error::out_of_range("vo-radius", radius, "> 0 world units"));
            }
        }
        if !(self.thickness_world.is_finite() && self.thickness_world >= 0.0) {
            return Err(crate::Error::out_of_range("thickness", self.thickness_world, "≥ 0 world units"));
        }
        Ok(())
    }
}

/// VO's radius (zoom units) in `preset` (docs/ground-truth.md), the radii being the sampling's
/// own: line samples legible 2 and physical 1.5, area samples 1 and 1; the strength it is shown
/// with.
pub(crate) fn preset(
    preset: Preset,
    vo: &mut VoSettings,
    context: &Context,
    legible_radius: f32,
    physical_radius: f32,
) -> f32 {
    let (strength, radius) = match preset {
        Preset::Paper => (1.0, 2.0),
        Preset::Legible => (0.8, legible_radius),
        Preset::Physical => (0.22, physical_radius),
        Preset::Sparse => (0.8, 6.0),
    };
    vo.radius_world = radius * context.zoom_unit;
    strength
}
