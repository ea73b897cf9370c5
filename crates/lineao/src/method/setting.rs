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

/// One setting of a method.
pub struct Setting {
    /// The command line's flag without its dashes (`ssao-samples`): the web page's URL key too;
    /// Python's keyword is it with `_` ([`Setting::keyword`]).
    pub flag: &'static str,
    /// Its name in a method's panel of controls (`samples`).
    pub label: &'static str,
    /// One line of help: what it changes (the unit, range and default are added from the
    /// fields below).
    pub help: &'static str,
    /// What it is counted in (`"zoom units"`, `"px"`), or `""`.
    pub unit: &'static str,
    /// Its values.
    pub kind: Kind,
    /// Its value in `settings`.
    pub get: fn(&ChainSettings) -> Value,
    /// Puts `value` (of its [`Setting::kind`]) into `settings`.
    pub set: fn(&mut ChainSettings, Value),
}

/// What values a [`Setting`] takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A number in `min..=max`; `log`: a slider moves it by factors.
    Number { min: f32, max: f32, log: bool },
    /// A whole number in `min..=max`.
    Count { min: u32, max: u32 },
    /// On or off. The flag sets it to `given` (`--no-normal-clamp` gives `false`), so its
    /// default is the other.
    Switch { given: bool },
}

/// A [`Setting`]'s value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Number(f32),
    Count(u32),
    Switch(bool),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Number(x) => write!(f, "{x}"),
            Value::Count(n) => write!(f, "{n}"),
            Value::Switch(on) => f.write_str(if *on { "on" } else { "off" }),
        }
    }
}

impl Value {
    /// The number; a switch is 0 or 1.
    pub fn as_f32(self) -> f32 {
        match self {
            Value::Number(x) => x,
            Value::Count(n) => n as f32,
            Value::Switch(on) => f32::from(u8::from(on)),
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
    /// Python's keyword argument: the flag with `_` (`ssao_samples`).
    pub fn keyword(&self) -> String {
        self.flag.replace('-', "_")
    }

    /// Its value where nothing changes it: in the default preset's settings with its method
    /// shown ([`ChainSettings::default`]; a preset may change a method's own values).
    pub fn default_value(&self, method: super::AoMethod) -> Value {
        (self.get)(&ChainSettings { method, ..ChainSettings::papers() }.with_preset(crate::Preset::default()))
    }

    /// Its range in words (`0.05..=4 zoom units`), or `None` for a switch.
    pub fn range(&self) -> Option<String> {
        let unit = if self.unit.is_empty() { String::new() } else { format!(" {}", self.unit) };
        match self.kind {
            Kind::Number { min, max, .. } => Some(format!("{min}..={max}{unit}")),
            Kind::Count { min, max } => Some(format!("{min}..={max}{unit}")),
            Kind::Switch { .. } => None,
        }
    }

    /// `text` as the command line writes it (`2.5`, `16`; a switch `on`/`off`, `true`/`false`),
    /// within the range: the error says what was expected.
    pub fn parse(&self, text: &str) -> Result<Value, String> {
        let text = text.trim();
        let value = match self.kind {
            Kind::Number { .. } => Value::Number(text.parse().map_err(|_| format!("expected a number, got '{text}'"))?),
            Kind::Count { .. } => {
                Value::Count(text.parse().map_err(|_| format!("expected a whole number, got '{text}'"))?)
            }
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
            (Kind::Number { min, max, .. }, Value::Number(x)) => (min..=max).contains(&x),
            (Kind::Count { min, max }, Value::Count(n)) => (min..=max).contains(&n),
            (Kind::Switch { .. }, Value::Switch(_)) => true,
            _ => false,
        };
        if fits {
            return Ok(());
        }
        let (min, max) = match self.kind {
            Kind::Number { min, max, .. } => (f64::from(min), f64::from(max)),
            Kind::Count { min, max } => (f64::from(min), f64::from(max)),
            Kind::Switch { .. } => (0.0, 1.0),
        };
        Err(crate::Error::OutOfRange {
            setting: self.flag,
            value: f64::from(value.as_f32()),
            min,
            max,
            unit: self.unit,
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
        let mut flags = std::collections::BTreeSet::new();
        for &method in AoMethod::REGISTRY {
            for s in method.info().settings {
                assert!(flags.insert(s.flag), "{} is given twice", s.flag);
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
                let other = match s.kind {
                    Kind::Number { min, max, .. } => Value::Number(0.5 * (min + max)),
                    Kind::Count { max, .. } => Value::Count(max),
                    Kind::Switch { given } => Value::Switch(given),
                };
                let mut chain = ChainSettings { method, ..ChainSettings::default() };
                (s.set)(&mut chain, other);
                assert_eq!((s.get)(&chain), other, "{}", s.flag);
                assert_eq!(s.parse(&other.to_string()).unwrap(), other, "{}", s.flag);
                if let Kind::Number { max, .. } = s.kind {
                    (s.set)(&mut chain, Value::Number(2.0 * max + 1.0));
                    let refused = chain.validate().unwrap_err().to_string();
                    assert!(refused.contains(&format!("--{}", s.flag)), "{refused}");
                    assert!(s.parse("x").is_err());
                }
            }
        }
    }
}
