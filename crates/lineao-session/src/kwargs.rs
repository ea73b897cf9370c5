//! `render`'s arguments from typed values — Python's keyword arguments, as JSON — without a
//! command line: [`RenderArgs`] deserializes with serde, each option's value parsed by the
//! same function the command line parses it with (a method name, `20%`, `x,y,z`, a settings
//! object), its defaults the command line's, and every error names the keyword.

use std::collections::BTreeSet;
use std::sync::OnceLock;

use clap::Args;
use serde::Deserialize;

use crate::args::RenderArgs;
use crate::text::Text;

/// A keyword argument of `render`: its name (the option's with `_`), help and default.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyword {
    pub name: String,
    pub help: String,
    pub default: Option<String>,
}

/// What a keyword argument got wrong.
#[derive(Debug, PartialEq)]
pub enum KwargError {
    /// A name `render` does not take (Python: `TypeError`).
    Unknown { name: String, known: Vec<String> },
    /// A value its option refuses, or options that exclude or need each other (`ValueError`).
    Invalid(String),
}

impl std::fmt::Display for KwargError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            KwargError::Unknown { name, known } => {
                write!(f, "unexpected keyword argument '{name}'; the settings are: {}", known.join(", "))
            }
            KwargError::Invalid(text) => f.write_str(text),
        }
    }
}

impl std::error::Error for KwargError {}

impl Default for RenderArgs {
    /// The command line's defaults (`lineao render` with no option): one definition for both,
    /// parsed once (serde asks for them once per group on every call of
    /// [`RenderArgs::from_keywords`], which Python makes every frame).
    fn default() -> RenderArgs {
        static DEFAULTS: OnceLock<RenderArgs> = OnceLock::new();
        DEFAULTS
            .get_or_init(|| {
                let command = RenderArgs::augment_args(clap::Command::new("render").no_binary_name(true));
                let matches =
                    command.try_get_matches_from(std::iter::empty::<&str>()).expect("every option has a default");
                <RenderArgs as clap::FromArgMatches>::from_arg_matches(&matches).expect("the defaults parse")
            })
            .clone()
    }
}

impl RenderArgs {
    /// The keyword arguments `render` takes: its options without the output file, each with
    /// its help and default, read from the command line's definition.
    pub fn keywords() -> Vec<Keyword> {
        let command = RenderArgs::augment_args(clap::Command::new("render"));
        let options = command
            .get_arguments()
            .filter(|a| a.get_long().is_some() && !matches!(a.get_id().as_str(), "output" | "help"));
        options
            .map(|a| Keyword {
                name: a.get_id().to_string(),
                help: a.get_help().map(|h| h.to_string()).unwrap_or_default(),
                default: a.get_default_values().first().map(|d| d.to_string_lossy().into_owned()),
            })
            .collect()
    }

    /// The arguments from `values` (a JSON object of keyword arguments; `None`s left out),
    /// checked as the command line checks them: each value by its option's parser, the ranges,
    /// and the options that exclude or need each other.
    pub fn from_keywords(values: serde_json::Map<String, serde_json::Value>) -> Result<RenderArgs, KwargError> {
        static KNOWN: OnceLock<Vec<String>> = OnceLock::new();
        let known = KNOWN.get_or_init(|| RenderArgs::keywords().into_iter().map(|k| k.name).collect());
        if let Some(name) = values.keys().find(|name| !known.contains(name)) {
            return Err(KwargError::Unknown { name: name.clone(), known: known.clone() });
        }
        // A switch set to False is a switch not given, as on the command line.
        let given: BTreeSet<String> =
            values.iter().filter(|(_, v)| **v != serde_json::Value::Bool(false)).map(|(k, _)| k.clone()).collect();
        let args: RenderArgs = match serde_json::from_value(serde_json::Value::Object(values.clone())) {
            Ok(args) => args,
            // The groups are flattened, so serde's error has lost the key: the first keyword
            // that fails alone is the one to name.
            Err(e) => {
                let alone = |(key, value): (&String, &serde_json::Value)| {
                    let one = serde_json::Map::from_iter([(key.clone(), value.clone())]);
                    serde_json::from_value::<RenderArgs>(serde_json::Value::Object(one))
                        .err()
                        .map(|e| format!("{key}: {e}"))
                };
                return Err(KwargError::Invalid(values.iter().find_map(alone).unwrap_or_else(|| e.to_string())));
            }
        };
        args.check(&given).map_err(KwargError::Invalid)?;
        Ok(args)
    }

    /// What clap's attributes check on the command line: the ranges of the counted options and
    /// the options that exclude (`conflicts_with`) or need (`requires`) another.
    fn check(&self, given: &BTreeSet<String>) -> Result<(), String> {
        let ranges = [
            ("width", self.image.width, 1, crate::args::MAX_SIDE),
            ("height", self.image.height, 1, crate::args::MAX_SIDE),
            ("volume_resolution", self.volume.volume_resolution, 8, 1024),
            ("turntable", self.figure.turntable.unwrap_or(1), 1, 100_000),
            ("fps", self.figure.fps, 1, 240),
        ];
        for (name, value, lo, hi) in ranges {
            if !(lo..=hi).contains(&value) {
                return Err(format!("invalid value '{value}' for '{name}': {value} is not in {lo}..={hi}"));
            }
        }
        let has = |name: &str| given.contains(name);
        // The conflicts are clap's own (`conflicts_with`); clap keeps `requires` to itself, so
        // those are listed here, and a test holds the list to what the command line refuses.
        static CONFLICTS: OnceLock<Vec<(String, String)>> = OnceLock::new();
        let conflicts = CONFLICTS.get_or_init(|| {
            let command = RenderArgs::augment_args(clap::Command::new("render"));
            let pairs = command.get_arguments().flat_map(|a| {
                let others = command.get_arg_conflicts_with(a).into_iter().map(|b| b.get_id().to_string());
                others.map(|b| (a.get_id().to_string(), b)).collect::<Vec<_>>()
            });
            pairs.collect()
        });
        if let Some((a, b)) = conflicts.iter().find(|(a, b)| has(a) && has(b)) {
            return Err(format!("'{a}' cannot be used with '{b}'"));
        }
        for (a, b) in REQUIRES {
            if has(a) && !has(b) {
                return Err(format!("'{a}' needs '{b}'"));
            }
        }
        Ok(())
    }
}

/// The options that need another (clap's `requires`, which it does not expose).
const REQUIRES: [(&str, &str); 9] = [
    ("combine", "radius2"),
    ("bilateral_radius", "bilateral"),
    ("bilateral_sigma", "bilateral"),
    ("slices", "volume"),
    ("window", "volume"),
    ("opaque_slices", "volume"),
    ("turntable_degrees", "turntable"),
    ("movie", "turntable"),
    ("fps", "turntable"),
];

/// `deserialize_with` functions: the value's text through the command line's parser of the
/// option (`opt_…` for an optional one).
macro_rules! parsed {
    ($($name:ident: $ty:ty = $parse:path;)*) => {$(
        pub(crate) fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<$ty, D::Error> {
            let Text(text) = Text::deserialize(d)?;
            $parse(&text).map_err(serde::de::Error::custom)
        }
    )*};
}

macro_rules! optional {
    ($($name:ident: $ty:ty = $parse:path;)*) => {$(
        pub(crate) fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<$ty>, D::Error> {
            let Text(text) = Text::deserialize(d)?;
            $parse(&text).map(Some).map_err(serde::de::Error::custom)
        }
    )*};
}

parsed! {
    scene: lineao_tracts::SceneKind = crate::args::parse_scene;
    method: crate::args::Method = crate::args::parse_method;
    vec3: [f32; 3] = crate::args::parse_vec3;
    preset: lineao::Preset = crate::args::parse_preset;
    color: crate::args::ColorArg = crate::args::parse_color;
    debug_view: lineao::DebugView = crate::args::parse_debug_view;
    geometry: crate::args::GeometryArg = crate::args::parse_value_enum::<crate::args::GeometryArg>;
    sky: crate::args::SkyArg = crate::args::parse_value_enum::<crate::args::SkyArg>;
    volume_normal: crate::args::VolumeNormal = crate::args::parse_value_enum::<crate::args::VolumeNormal>;
}

optional! {
    opt_pair: [crate::args::Method; 2] = crate::args::parse_pair;
    opt_vec3: [f32; 3] = crate::args::parse_vec3;
    opt_positive: f32 = crate::args::parse_positive;
    opt_slices: [Option<f32>; 3] = crate::args::parse_slices;
    opt_window: [f32; 2] = crate::args::parse_window;
    opt_slab: lineao::Slab = crate::args::parse_slab;
    opt_share: f64 = crate::args::parse_share;
    opt_field_range: (String, [f32; 2]) = crate::args::parse_field_range;
    opt_tile: u32 = crate::args::parse_tile;
}

/// A repeatable option: one value (its text) or a sequence of values, each through `parse`.
fn repeated<'de, D: serde::Deserializer<'de>, T>(
    d: D,
    parse: fn(&str) -> Result<T, String>,
) -> Result<Vec<T>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum OneOrMany {
        One(String),
        Many(Vec<String>),
    }
    let texts = match OneOrMany::deserialize(d)? {
        OneOrMany::One(text) => vec![text],
        OneOrMany::Many(texts) => texts,
    };
    texts.iter().map(|t| parse(t)).collect::<Result<_, _>>().map_err(serde::de::Error::custom)
}

/// `group`: one name or several.
pub(crate) fn strings<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<String>, D::Error> {
    repeated(d, |s| Ok(s.to_string()))
}

/// `views`: one name, a list of names, or names separated by commas.
pub(crate) fn views<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<crate::cameras::AnatomicalView>, D::Error> {
    let names = repeated(d, |s| Ok(s.to_string()))?;
    let views = names.iter().flat_map(|n| n.split(',')).map(crate::cameras::parse_view);
    views.collect::<Result<_, _>>().map_err(serde::de::Error::custom)
}

/// `orbit`: one AZIMUTH,ELEVATION,ZOOM (text or three numbers) or several (a list of them).
pub(crate) fn orbits<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<[f32; 3]>, D::Error> {
    let value = serde_json::Value::deserialize(d)?;
    let items = match &value {
        serde_json::Value::Array(items) if items.iter().all(|i| !i.is_number()) => items.clone(),
        _ => vec![value],
    };
    let texts = items.into_iter().map(|item| Text::deserialize(item).map(|Text(t)| t));
    let texts: Vec<String> = texts.collect::<Result<_, _>>().map_err(serde::de::Error::custom)?;
    texts.iter().map(|t| crate::cameras::parse_orbit(t)).collect::<Result<_, _>>().map_err(serde::de::Error::custom)
}

/// `include`, `exclude`: one region or several.
pub(crate) fn regions<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<lineao_tracts::Region>, D::Error> {
    repeated(d, crate::args::parse_region)
}

/// `settings`: an object of `ChainSettings` keys, or the command line's text (JSON or a file).
pub(crate) fn opt_settings<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Option<crate::args::SettingsPatch>, D::Error> {
    let text = match serde_json::Value::deserialize(d)? {
        serde_json::Value::String(s) => s,
        value => value.to_string(),
    };
    crate::args::parse_settings(&text).map(Some).map_err(serde::de::Error::custom)
}

/// `surfaces`: one file or several.
pub(crate) fn paths<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<std::path::PathBuf>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum OneOrMany {
        One(std::path::PathBuf),
        Many(Vec<std::path::PathBuf>),
    }
    Ok(match OneOrMany::deserialize(d)? {
        OneOrMany::One(path) => vec![path],
        OneOrMany::Many(paths) => paths,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn from(value: serde_json::Value) -> Result<RenderArgs, KwargError> {
        RenderArgs::from_keywords(value.as_object().unwrap().clone())
    }

    fn parsed(argv: &[&str]) -> RenderArgs {
        *crate::args::parse_render(["lineao", "render"].iter().chain(argv))
    }

    #[test]
    fn keywords_parse_as_the_command_line_parses_them() {
        let args = from(json!({
            "width": 320, "line_width": 3, "compare": ["lineao", "ssao"], "background": [0, 0, 0.5],
            "ao_distance": "20%", "color": "tangent", "eye": "1,2,3", "grid": false, "surfaces": "brain.obj",
            "settings": {"ssao": {"samples": 12}}, "method": "lineao+sweep", "debug_view": "level:1",
        }))
        .unwrap();
        let expected = parsed(&[
            "--width",
            "320",
            "--line-width",
            "3",
            "--compare",
            "lineao,ssao",
            "--background",
            "0,0,0.5",
            "--ao-distance",
            "20%",
            "--eye",
            "1,2,3",
            "--surface",
            "brain.obj",
            "--settings",
            r#"{"ssao": {"samples": 12}}"#,
            "--method",
            "lineao+sweep",
            "--debug-view",
            "level:1",
        ]);
        assert_eq!(format!("{args:?}"), format!("{expected:?}"));
        // No keyword: the command line's defaults.
        assert_eq!(format!("{:?}", from(json!({})).unwrap()), format!("{:?}", parsed(&[])));
    }

    /// What `check` lists by hand (the ranges, `requires`) the command line refuses too.
    #[test]
    fn the_hand_listed_checks_are_the_command_lines() {
        let refuses = |argv: &[&str]| crate::args::try_parse_render(["lineao", "render"].iter().chain(argv)).is_err();
        let flag = |name: &str| format!("--{}", name.replace('_', "-"));
        for (a, b) in REQUIRES {
            let value = match a {
                "combine" => "min",
                "slices" => "1,2,3",
                "window" => "0,1",
                _ => "1",
            };
            assert!(refuses(&[&flag(a), value]), "{a} without {b}");
            assert!(from(json!({a: value})).is_err(), "{a} without {b}");
        }
        for (name, out) in [
            ("width", 0),
            ("width", 65537),
            ("height", 0),
            ("s_h", 257),
            ("volume_resolution", 7),
            ("rays", 0),
            ("turntable", 0),
        ] {
            let text = out.to_string();
            assert!(refuses(&[&flag(name), &text]), "{name} {out}");
            assert!(from(json!({name: out})).is_err(), "{name} {out}");
        }
    }

    #[test]
    fn every_error_names_its_keyword() {
        let err = |v| from(v).unwrap_err().to_string();
        assert!(
            err(json!({"linewidth": 2})).starts_with("unexpected keyword argument 'linewidth'; the settings are: ")
        );
        assert_eq!(err(json!({"width": 0})), "invalid value '0' for 'width': 0 is not in 1..=65536");
        assert!(
            err(json!({"method": "bogus"})).starts_with("method: unknown method 'bogus'"),
            "{}",
            err(json!({"method": "bogus"}))
        );
        assert!(err(json!({"line_width": "thick"})).starts_with("line_width: invalid type"));
        assert!(err(json!({"settings": {"ssao": {"sample": 12}}})).contains("ssao.sample: unknown field `sample`"));
        assert!(err(json!({"ssao_radius": -1})).starts_with("ssao_radius: "));
        assert_eq!(err(json!({"compare": ["lineao", "ssao"], "grid": true})), "'compare' cannot be used with 'grid'");
        assert_eq!(err(json!({"combine": "min"})), "'combine' needs 'radius2'");
        assert!(err(json!({"eye": [1, 2]})).starts_with("eye: expected three numbers"));
    }
}
