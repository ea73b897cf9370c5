//! The registry: what it holds of each method ([`AoMethod::info`]: its folder's `METHOD`), the
//! names and help every front end lists, and what the chain's settings do through every
//! method's own (presets, validation, the pyramid's levels). It stands on top of the method
//! folders, which it lists ([`super::list`]).

use super::info::{BenchPass, ChainSetting, MethodInfo, Stage};
use super::list::{AoMethod, for_each_method};
use super::setting;
use crate::preset::Preset;
use crate::settings::ChainSettings;

/// Makes [`AoMethod::info`] of the list: each method's folder's `METHOD`.
macro_rules! registry {
    ($( $(#[doc = $doc:literal])* $(#[cfg($cfg:meta)])? $variant:ident => $folder:ident $({ $($own:tt)* })? ),+ $(,)?) => {
        impl AoMethod {
            /// What the registry holds for the method.
            pub fn info(self) -> &'static MethodInfo {
                match self {
                    $( $(#[cfg($cfg)])? AoMethod::$variant => &crate::method::$folder::METHOD, )+
                }
            }
        }
    };
}

for_each_method!(registry);

impl AoMethod {
    /// The name used on the command line and in `params.json`.
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// The screen-space methods, in the order `--grid` shows them (not the ray-traced truth,
    /// which is progressive and needs the scene).
    pub fn screen_space() -> impl Iterator<Item = AoMethod> {
        AoMethod::REGISTRY.iter().copied().filter(|m| m.info().screen_space)
    }

    /// The method called `name`.
    pub fn from_name(name: &str) -> Option<AoMethod> {
        AoMethod::REGISTRY.iter().copied().find(|m| m.name() == name)
    }

    /// Every method's name, comma-separated: what an error about an unknown one lists.
    pub fn names() -> String {
        AoMethod::REGISTRY.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
    }
}

crate::named::serde_by_name!(AoMethod);

/// The registry's names and help, as every other setting with a fixed set of values.
impl crate::named::Named for AoMethod {
    const VALUES: &'static [AoMethod] = AoMethod::REGISTRY;

    fn name(self) -> &'static str {
        self.info().name
    }

    fn help(self) -> &'static str {
        self.info().help
    }
}

impl std::fmt::Display for AoMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

crate::named::from_str_by_name!(AoMethod, "method");

/// The spans of a timed frame, in chain order (docs/reference.md): the geometry, every method's, the
/// blur, object-space AO and the composite.
pub fn pass_names() -> Vec<&'static str> {
    let methods = AoMethod::REGISTRY.iter().flat_map(|m| m.info().spans.iter().copied());
    let mut names: Vec<&'static str> = std::iter::once("lines").chain(methods).collect();
    names.dedup();
    names.extend(["blur", "volume-ao", "composite", "transparency"]);
    names
}

/// Every method's bench passes, in the registry's order.
pub fn bench_passes() -> impl Iterator<Item = (AoMethod, &'static BenchPass)> {
    AoMethod::REGISTRY.iter().flat_map(|&m| m.info().bench.iter().map(move |pass| (m, pass)))
}

impl BenchPass {
    /// The stage it times, for `method` (whose registry entry lists it).
    pub fn stage(&self, method: AoMethod, device: &wgpu::Device, settings: &ChainSettings) -> Option<Box<dyn Stage>> {
        self.build.or(method.info().build).map(|build| build(device, settings))
    }
}

/// The stage of `settings`' method; `None` for a method without passes.
pub fn build(device: &wgpu::Device, settings: &ChainSettings) -> Option<Box<dyn Stage>> {
    settings.method.info().build.map(|build| build(device, settings))
}

impl ChainSetting {
    /// Its value where nothing changes it: in the default preset's settings with its method
    /// shown ([`ChainSettings::default`]; a preset may change a method's own values).
    pub fn default_value(&self, method: AoMethod) -> setting::Value {
        self.get(&ChainSettings { method, ..ChainSettings::papers() }.with_preset(Preset::default()))
    }
}

/// What the chain's settings do through every method's own.
impl ChainSettings {
    /// Whether the culled lines and tubes are drawn at levels of detail: [`ChainSettings::lod`],
    /// but never for a method that traces the scene (the GPU ray tracer), whose rays start on
    /// the G-buffer's lines and must find them where the scene it traces has them.
    pub fn levels_of_detail(&self) -> bool {
        self.lod && !self.method.info().traces_scene
    }

    /// `self` with `preset`'s values for its method (and LineAO variant): the strength and the
    /// method's own reach (each method's `preset` in its folder: LineAO's s_r, δ scale and r0,
    /// VO's and SSAO's radius in zoom units). Every other method's values are the papers'.
    /// [`Preset::Paper`] restores the papers' values of those ([`ChainSettings::papers`]).
    pub fn with_preset(mut self, preset: Preset) -> ChainSettings {
        for method in AoMethod::REGISTRY {
            method.info().own.preset(Preset::Paper, &mut self);
        }
        self.method.info().own.preset(preset, &mut self);
        self
    }

    /// `self` with every method's own values at `preset`, each as it is shown alone, and the
    /// strength of its method's: what panels that share one chain's settings and show
    /// different methods start from (the viewer). Else as [`ChainSettings::with_preset`].
    pub fn with_preset_for_every_method(self, preset: Preset) -> ChainSettings {
        let strength = self.clone().with_preset(preset).strength;
        let mut every = self.with_preset(Preset::Paper);
        for method in AoMethod::REGISTRY {
            method.info().own.preset(preset, &mut every);
        }
        every.strength = strength;
        every
    }

    /// Pyramid levels the chain needs: what its method reads (s_r for LineAO, one for the
    /// others and for LineAO's `reference` variant).
    pub fn levels(&self) -> u32 {
        self.method.info().own.levels(self)
    }

    /// Checks every range documented on the settings, every method's (whichever runs: settings
    /// are switched between methods), naming the one out of range.
    pub fn validate(&self) -> Result<(), crate::Error> {
        self.validate_chain()?;
        for method in AoMethod::REGISTRY {
            method.info().own.validate(self)?;
        }
        if let crate::DebugView::Level(k) = self.debug_view
            && k >= self.levels()
        {
            let expected = format!("a level of the pyramid's: level:0 to level:{}", self.levels() - 1);
            return Err(crate::Error::out_of_range("debug-view", format!("level:{k}"), &expected));
        }
        Ok(())
    }
}

impl Default for ChainSettings {
    /// The default preset's settings ([`Preset::Legible`], what every front end starts from):
    /// the papers' values ([`ChainSettings::papers`]) with the preset's for LineAO.
    fn default() -> Self {
        ChainSettings::papers().with_preset(Preset::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_round_trip() {
        for &method in AoMethod::REGISTRY {
            assert_eq!(AoMethod::from_name(method.name()), Some(method));
            assert_eq!(method.name().parse::<AoMethod>(), Ok(method));
            let same = AoMethod::REGISTRY.iter().filter(|m| m.name() == method.name()).count();
            assert_eq!(same, 1, "{method}");
        }
        assert!("gtao".parse::<AoMethod>().unwrap_err().contains("lineao, vo-line"));
    }

    /// Every described setting: a flag of lower-case words, help, a default in its range, a
    /// value that round-trips through `set` and `get` and through the text the flag takes.
    #[test]
    fn every_description_holds_its_own_default_and_reads_back_what_it_writes() {
        let mut flags = std::collections::BTreeMap::new();
        for &method in AoMethod::REGISTRY {
            for s in method.info().settings() {
                // Two methods may list one setting (VO's sphere): one flag, one description.
                let help = *flags.entry(s.flag).or_insert(s.help);
                assert_eq!(help, s.help, "{} describes two settings", s.flag);
                assert!(
                    s.flag.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-'),
                    "{}",
                    s.flag
                );
                assert!(!s.help.is_empty(), "{}", s.flag);
                let default = s.default_value(method);
                s.check(default).unwrap();
                if let setting::Kind::Switch { given } = s.kind {
                    assert_eq!(default, setting::Value::Switch(!given), "{}: the flag changes the default", s.flag);
                }
                // A value other than the default (where the kind has one), within range.
                let other = match s.kind {
                    setting::Kind::Number { min, max, .. } => setting::Value::Number(0.5 * (min + max)),
                    setting::Kind::Above { slider, .. } => setting::Value::Number(slider[1]),
                    setting::Kind::Count { max, .. } => setting::Value::Count(max),
                    setting::Kind::Counts(counts) => setting::Value::Count(counts[counts.len() - 1]),
                    setting::Kind::Choice(names) => setting::Value::Choice(names[names.len() - 1]),
                    setting::Kind::Switch { given } => setting::Value::Switch(given),
                    setting::Kind::Reach { slider } => setting::Value::Number(slider[1]),
                };
                let mut chain = ChainSettings { method, ..ChainSettings::default() };
                s.set(&mut chain, other);
                assert_eq!(s.get(&chain), other, "{}", s.flag);
                assert_eq!(s.parse(&other.to_string()).unwrap(), other, "{}", s.flag);
                let outside = match s.kind {
                    setting::Kind::Number { max, .. } => Some(setting::Value::Number(2.0 * max + 1.0)),
                    setting::Kind::Above { min, .. } => Some(setting::Value::Number(min - 1.0)),
                    setting::Kind::Count { max, .. } => max.checked_add(1).map(setting::Value::Count),
                    setting::Kind::Reach { .. } => Some(setting::Value::Share(1.5)),
                    _ => None,
                };
                if let Some(outside) = outside {
                    s.set(&mut chain, outside);
                    if s.get(&chain) != outside {
                        // Taken as something valid (VO's `radius2` ≤ 0: none).
                        continue;
                    }
                    let refused = chain.validate().unwrap_err().to_string();
                    assert!(refused.contains(&format!("--{}", s.flag)), "{refused}");
                    assert!(s.parse("x").is_err());
                }
            }
        }
    }

    #[test]
    fn every_span_is_timed_once_in_chain_order() {
        let names = pass_names();
        let mut unique = names.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{names:?}");
        for &method in AoMethod::REGISTRY {
            for span in method.info().spans {
                assert!(names.contains(span), "{method}: {span}");
            }
        }
        assert_eq!(names.first(), Some(&"lines"));
        // The transparent lines blend over the composite's picture: after it.
        assert_eq!(names[names.len() - 2..], ["composite", "transparency"]);
    }
}
