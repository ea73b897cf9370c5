//! A method's settings as they describe themselves: for each, the flag it is given by, its
//! help, unit, range and default, and how it is read from and written to a [`ChainSettings`].
//!
//! A method lists its settings in its [`super::MethodInfo::settings`]; from that one table the
//! front ends make what a user sees — the command line's flags (`lineao render --help` shows
//! each with its unit and default), Python's keyword arguments (the flag with `_`), the
//! viewer's sliders and checkboxes, the web page's URL keys (the flag) — and the chain checks
//! each value against its range ([`ChainSettings::validate`]), naming the flag. The `--settings`
//! JSON is the settings type's own serde: the method's field of [`ChainSettings`], which its
//! registry line declares.

use crate::settings::ChainSettings;

/// One setting of a method. [`Setting::BASE`] fills what most leave as it is:
/// `Setting { flag: "…", …, ..Setting::BASE }`.
pub struct Setting {
    /// The command line's flag without its dashes (`ssao-samples`): the web page's URL key too;
    /// Python's keyword is it with `_` ([`Setting::keyword`]).
    pub flag: &'static str,
    /// Its name in a method's panel of controls (`samples`).
    pub label: &'static str,
    /// One line of help: what it changes (the unit, range and default are added from the
    /// fields below).
    pub help: &'static str,
    /// What it is counted in.
    pub unit: Unit,
    /// Its values.
    pub kind: Kind,
    /// What the help says of its default where that is not one value (`"the preset's; paper
    /// 2"`, `"the radius"`); `None`: its value in [`ChainSettings::default`].
    pub default: Option<&'static str>,
    /// The command line's shorthand that gives it too where its method is shown.
    pub role: Option<Role>,
    /// The flag it means nothing without (VO's `combine` needs `radius2`): the command line
    /// refuses it alone.
    pub requires: Option<&'static str>,
    /// Whether it means anything under these settings (LineAO's base radius only in its
    /// `reference` variant): a panel shows it only then.
    pub applies: fn(&ChainSettings) -> bool,
    /// Its value in `settings`.
    pub get: fn(&ChainSettings) -> Value,
    /// Puts `value` (of its [`Setting::kind`]) into `settings`.
    pub set: fn(&mut ChainSettings, Value),
}

/// What a [`Setting`] is counted in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// No unit (a count, a share, a choice).
    None,
    /// Pixels.
    Px,
    /// Zoom units (z(P)'s: 1 mm for tractograms).
    ZoomUnits,
    /// The data's units (mm for tractograms): a panel's slider spans its range times the zoom
    /// unit.
    WorldUnits,
}

impl Unit {
    /// Its name in help and errors (`""` for none).
    pub fn name(self) -> &'static str {
        match self {
            Unit::None => "",
            Unit::Px => "px",
            Unit::ZoomUnits => "zoom units",
            Unit::WorldUnits => "world units",
        }
    }
}

/// What values a [`Setting`] takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A number in `[min, max]`, or `(min, max]` where `open`; `log`: a slider moves it by
    /// factors.
    Number {
        /// The least value.
        min: f32,
        /// The greatest value.
        max: f32,
        /// Whether `min` itself is left out.
        open: bool,
        /// Whether a slider moves it by factors.
        log: bool,
    },
    /// Any finite number above `min` (`> min` where `open`, else `≥ min`); a panel's slider
    /// spans `slider` (by factors where `log`).
    Above {
        /// The bound below.
        min: f32,
        /// Whether `min` itself is left out.
        open: bool,
        /// What a panel's slider spans.
        slider: [f32; 2],
        /// Whether a slider moves it by factors.
        log: bool,
    },
    /// A whole number in `min..=max`.
    Count {
        /// The least value.
        min: u32,
        /// The greatest value.
        max: u32,
    },
    /// One of these whole numbers (VO's sample sets).
    Counts(&'static [u32]),
    /// One of these names ([`crate::Named`] values').
    Choice(&'static [&'static str]),
    /// On or off. The flag sets it to `given` (`--no-normal-clamp` gives `false`), so its
    /// default is the other.
    Switch {
        /// What the flag sets it to.
        given: bool,
    },
    /// A length > 0 ([`Value::Number`], in its unit), or a share in (0 %, 100 %] of the longest
    /// side of the scene's axis-aligned bounds written with `%` ([`Value::Share`]: the ray
    /// tracer's reach, LineVis's 20 %); a panel's slider spans `slider` by factors.
    Reach {
        /// What a panel's slider spans.
        slider: [f32; 2],
    },
}

/// The shorthands of the command line that give a setting of the method shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// `--samples`.
    Samples,
    /// `--radius`.
    Radius,
}

/// A [`Setting`]'s value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// A number, in the setting's unit.
    Number(f32),
    /// A whole number.
    Count(u32),
    /// One of the setting's names.
    Choice(&'static str),
    /// On or off.
    Switch(bool),
    /// A share of the scene's longest side ([`Kind::Reach`]), as a fraction (`20%`: 0.2).
    Share(f32),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Number(x) => write!(f, "{x}"),
            Value::Count(n) => write!(f, "{n}"),
            Value::Choice(name) => f.write_str(name),
            Value::Switch(on) => f.write_str(if *on { "on" } else { "off" }),
            Value::Share(share) => write!(f, "{}%", share * 100.0),
        }
    }
}

impl Value {
    /// The number (a share's fraction); a switch is 0 or 1, a choice NaN.
    pub fn as_f32(self) -> f32 {
        match self {
            Value::Number(x) | Value::Share(x) => x,
            Value::Count(n) => n as f32,
            Value::Choice(_) => f32::NAN,
            Value::Switch(on) => f32::from(u8::from(on)),
        }
    }

    /// The `T` it names (a choice; anything else: `T`'s default).
    pub fn named<T: crate::Named + Default>(self) -> T {
        match self {
            Value::Choice(name) => T::VALUES.iter().copied().find(|v| v.name() == name).unwrap_or_default(),
            _ => T::default(),
        }
    }

    /// The whole number (a number rounded down, a switch 0 or 1).
    pub fn as_u32(self) -> u32 {
        match self {
            Value::Count(n) => n,
            other => other.as_f32() as u32,
        }
    }

    /// Whether it is on (a number: not 0).
    pub fn is_on(self) -> bool {
        match self {
            Value::Switch(on) => on,
            other => other.as_f32() != 0.0,
        }
    }
}

impl Setting {
    /// What most settings leave as it is: no unit, their default value, no shorthand, always
    /// applying. (`kind`, `get` and `set` are each setting's own.)
    pub const BASE: Setting = Setting {
        flag: "",
        label: "",
        help: "",
        unit: Unit::None,
        kind: Kind::Switch { given: true },
        default: None,
        role: None,
        requires: None,
        applies: |_| true,
        get: |_| Value::Switch(false),
        set: |_, _| {},
    };

    /// Python's keyword argument: the flag with `_` (`ssao_samples`).
    pub fn keyword(&self) -> String {
        self.flag.replace('-', "_")
    }

    /// Its value where nothing changes it: in the default preset's settings with its method
    /// shown ([`ChainSettings::default`]; a preset may change a method's own values).
    pub fn default_value(&self, method: super::AoMethod) -> Value {
        (self.get)(&ChainSettings { method, ..ChainSettings::papers() }.with_preset(crate::Preset::default()))
    }

    /// Its range in words (`[0.25, 4] zoom units`, `(0, 1]`, `1..=256`, `> 0 world units`, `≥ 0 px`, `5, 7 or 9`, `crytek or
    /// sphere`), or `None` for a switch.
    pub fn range(&self) -> Option<String> {
        let unit = match self.unit.name() {
            "" => String::new(),
            name => format!(" {name}"),
        };
        let listed = |items: Vec<String>| match items.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => String::new(),
        };
        match self.kind {
            Kind::Number { min, max, open, .. } => Some(format!("{}{min}, {max}]{unit}", if open { "(" } else { "[" })),
            Kind::Above { min, open, .. } => Some(format!("{} {min}{unit}", if open { ">" } else { "≥" })),
            Kind::Count { min, max } => Some(format!("{min}..={max}{unit}")),
            Kind::Counts(counts) => Some(listed(counts.iter().map(u32::to_string).collect()) + &unit),
            Kind::Choice(names) => Some(listed(names.iter().map(|n| n.to_string()).collect())),
            Kind::Switch { .. } => None,
            Kind::Reach { .. } => Some(format!("> 0{unit}, or a share in (0 %, 100 %] of the scene's longest side")),
        }
    }

    /// `text` as the command line writes it (`2.5`, `16`, `20%`; a switch `on`/`off`,
    /// `true`/`false`), within the range: the error says what was expected.
    pub fn parse(&self, text: &str) -> Result<Value, String> {
        let text = text.trim();
        let number = |text: &str| text.trim().parse::<f32>().map_err(|_| format!("expected a number, got '{text}'"));
        let value = match self.kind {
            Kind::Reach { .. } => match text.strip_suffix('%') {
                Some(percent) => Value::Share(
                    percent.trim().parse::<f32>().map_err(|_| format!("expected a share such as 20%, got '{text}'"))?
                        / 100.0,
                ),
                None => Value::Number(number(text)?),
            },
            Kind::Number { .. } | Kind::Above { .. } => {
                Value::Number(text.parse().map_err(|_| format!("expected a number, got '{text}'"))?)
            }
            Kind::Count { .. } | Kind::Counts(_) => {
                Value::Count(text.parse().map_err(|_| format!("expected a whole number, got '{text}'"))?)
            }
            Kind::Choice(names) => match names.iter().find(|n| **n == text) {
                Some(name) => Value::Choice(name),
                None => return Err(format!("expected {}, got '{text}'", self.range().unwrap_or_default())),
            },
            Kind::Switch { .. } => Value::Switch(match text {
                "on" | "true" | "True" | "1" => true,
                "off" | "false" | "False" | "0" => false,
                _ => return Err(format!("expected on or off, got '{text}'")),
            }),
        };
        self.check(value).map_err(|e| e.to_string())?;
        Ok(value)
    }

    /// Whether `value` is of its kind and within its range; the error names the flag.
    pub fn check(&self, value: Value) -> Result<(), crate::Error> {
        let fits = match (self.kind, value) {
            (Kind::Number { min, max, open, .. }, Value::Number(x)) => (min..=max).contains(&x) && !(open && x == min),
            (Kind::Above { min, open, .. }, Value::Number(x)) => x.is_finite() && (x > min || (!open && x == min)),
            (Kind::Count { min, max }, Value::Count(n)) => (min..=max).contains(&n),
            (Kind::Counts(counts), Value::Count(n)) => counts.contains(&n),
            (Kind::Choice(names), Value::Choice(name)) => names.contains(&name),
            (Kind::Switch { .. }, Value::Switch(_)) => true,
            (Kind::Reach { .. }, Value::Number(x)) => x.is_finite() && x > 0.0,
            (Kind::Reach { .. }, Value::Share(share)) => share > 0.0 && share <= 1.0,
            _ => false,
        };
        if fits {
            return Ok(());
        }
        Err(crate::Error::OutOfRange {
            setting: self.flag,
            value: value.to_string(),
            expected: self.range().unwrap_or_default(),
        })
    }
}

/// Checks each of `settings`' values in `chain`: what the descriptions say of a method's
/// validation (its own function checks how its values depend on each other).
pub fn check_all(settings: &[Setting], chain: &ChainSettings) -> Result<(), crate::Error> {
    settings.iter().try_for_each(|s| s.check((s.get)(chain)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::AoMethod;

    /// Every described setting: a flag of lower-case words, help, a default in its range, a
    /// value that round-trips through `set` and `get` and through the text the flag takes.
    #[test]
    fn every_description_holds_its_own_default_and_reads_back_what_it_writes() {
        let mut flags = std::collections::BTreeMap::new();
        for &method in AoMethod::REGISTRY {
            for s in method.info().settings {
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
                if let Kind::Switch { given } = s.kind {
                    assert_eq!(default, Value::Switch(!given), "{}: the flag changes the default", s.flag);
                }
                // A value other than the default (where the kind has one), within range.
                let other = match s.kind {
                    Kind::Number { min, max, .. } => Value::Number(0.5 * (min + max)),
                    Kind::Above { slider, .. } => Value::Number(slider[1]),
                    Kind::Count { max, .. } => Value::Count(max),
                    Kind::Counts(counts) => Value::Count(counts[counts.len() - 1]),
                    Kind::Choice(names) => Value::Choice(names[names.len() - 1]),
                    Kind::Switch { given } => Value::Switch(given),
                    Kind::Reach { slider } => Value::Number(slider[1]),
                };
                let mut chain = ChainSettings { method, ..ChainSettings::default() };
                (s.set)(&mut chain, other);
                assert_eq!((s.get)(&chain), other, "{}", s.flag);
                assert_eq!(s.parse(&other.to_string()).unwrap(), other, "{}", s.flag);
                let outside = match s.kind {
                    Kind::Number { max, .. } => Some(Value::Number(2.0 * max + 1.0)),
                    Kind::Above { min, .. } => Some(Value::Number(min - 1.0)),
                    Kind::Count { max, .. } => max.checked_add(1).map(Value::Count),
                    Kind::Reach { .. } => Some(Value::Share(1.5)),
                    _ => None,
                };
                if let Some(outside) = outside {
                    (s.set)(&mut chain, outside);
                    if (s.get)(&chain) != outside {
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
}
