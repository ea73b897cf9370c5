//! The toy's settings: two, which the front ends show as flags, keywords, controls and URL keys
//! from their descriptions here.

use crate::method::setting::{About, Kind, Setting, Unit, Value};

/// The toy's settings: the `toy` field of the chain's settings (its registry line's).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ToySettings {
    /// A quarter of occlusion per zoom unit, 0.25..=4. Default 1.
    pub radius_zoom: f32,
    /// One minus that instead. Default off.
    pub invert: bool,
}

impl Default for ToySettings {
    fn default() -> Self {
        ToySettings { radius_zoom: 1.0, invert: false }
    }
}

impl ToySettings {
    /// The occlusion of every geometry pixel.
    pub fn occlusion(&self) -> f32 {
        let quarter = (0.25 * self.radius_zoom).min(1.0);
        if self.invert { 1.0 - quarter } else { quarter }
    }
}

pub(crate) const SETTINGS: &[Setting<ToySettings>] = &[
    Setting {
        about: About {
            flag: "toy-radius",
            label: "radius",
            help: "Toy: a quarter of occlusion per zoom unit",
            unit: Unit::ZoomUnits,
            kind: Kind::Number { min: 0.25, max: 4.0, open: false, log: true },
            ..About::BASE
        },
        get: |s, _| Value::Number(s.radius_zoom),
        set: |s, v| s.radius_zoom = v.as_f32(),
        ..Setting::BASE
    },
    Setting {
        about: About {
            flag: "toy-invert",
            label: "invert",
            help: "Toy: one minus that occlusion",
            kind: Kind::Switch { given: true },
            ..About::BASE
        },
        get: |s, _| Value::Switch(s.invert),
        set: |s, v| s.invert = v.is_on(),
        ..Setting::BASE
    },
];
